//! The ASF text parser behind [`Asf::parse`].

use std::path::Path;

use glam::DVec3;

use super::asf::{Asf, AsfBone, AsfRoot, AsfUnits, Dof};
use super::error::{parse_array, parse_num, PoseError};
use super::euler::Axis;

type Lines<'a> = [(usize, Vec<&'a str>)];

/// Parses ASF text; `path` is used in error messages.
pub(super) fn parse(text: &str, path: &Path) -> Result<Asf, PoseError> {
    let lines: Vec<(usize, Vec<&str>)> = text
        .lines()
        .enumerate()
        .filter_map(|(i, l)| {
            let l = l.split('#').next().unwrap_or("");
            let toks: Vec<&str> = l.split_whitespace().collect();
            (!toks.is_empty()).then_some((i + 1, toks))
        })
        .collect();
    let last_line = text.lines().count().max(1);
    let mut p = Parser {
        path,
        lines: &lines,
        last_line,
    };
    p.run()
}

struct Parser<'a, 'b> {
    path: &'a Path,
    lines: &'b Lines<'a>,
    last_line: usize,
}

struct RawBone {
    line: usize,
    id: Option<i64>,
    name: Option<String>,
    direction: Option<DVec3>,
    length: Option<f64>,
    axis: DVec3,
    axis_order: [Axis; 3],
    dofs: Vec<Dof>,
    limits: Vec<f64>,
    limits_line: usize,
}

impl<'a> Parser<'a, '_> {
    fn err(&self, line: usize, msg: impl Into<String>) -> PoseError {
        PoseError::parse(self.path, line, msg)
    }

    /// Index of the next line that starts a section, from `i`.
    fn section_end(&self, mut i: usize) -> usize {
        while i < self.lines.len() && !self.lines[i].1[0].starts_with(':') {
            i += 1;
        }
        i
    }

    fn run(&mut self) -> Result<Asf, PoseError> {
        let mut name = String::new();
        let mut units = AsfUnits {
            mass: 1.0,
            length: 1.0,
            degrees: true,
        };
        let mut root: Option<AsfRoot> = None;
        let mut raw: Option<Vec<RawBone>> = None;
        let mut hierarchy: Option<Vec<(usize, Vec<&str>)>> = None;
        let mut i = 0;
        while i < self.lines.len() {
            let (ln, toks) = &self.lines[i];
            let key = toks[0].to_ascii_lowercase();
            match key.as_str() {
                ":version" => i += 1,
                ":name" => {
                    name = toks[1..].join(" ");
                    i += 1;
                }
                ":units" => {
                    let end = self.section_end(i + 1);
                    self.units(&self.lines[i + 1..end], &mut units)?;
                    i = end;
                }
                ":root" => {
                    let end = self.section_end(i + 1);
                    root = Some(self.root(&self.lines[i + 1..end])?);
                    i = end;
                }
                ":bonedata" => {
                    let (bones, next) = self.bonedata(i + 1)?;
                    raw = Some(bones);
                    i = next;
                }
                ":hierarchy" => {
                    let (h, next) = self.hierarchy(*ln, i + 1)?;
                    hierarchy = Some(h);
                    i = next;
                }
                k if k.starts_with(':') => i = self.section_end(i + 1),
                _ => {
                    return Err(self.err(
                        *ln,
                        format!(
                            "expected a section keyword such as ':root', found '{}'",
                            toks[0]
                        ),
                    ))
                }
            }
        }
        let last = self.last_line;
        let root = root.ok_or_else(|| self.err(last, "missing section :root (truncated file?)"))?;
        let raw =
            raw.ok_or_else(|| self.err(last, "missing section :bonedata (truncated file?)"))?;
        let hierarchy = match hierarchy {
            Some(h) => h,
            None if raw.is_empty() => Vec::new(),
            None => return Err(self.err(last, "missing section :hierarchy (truncated file?)")),
        };
        self.finish(name, units, root, raw, hierarchy)
    }

    fn units(&self, lines: &Lines, units: &mut AsfUnits) -> Result<(), PoseError> {
        for (ln, toks) in lines {
            if toks.len() != 2 {
                return Err(self.err(
                    *ln,
                    format!("units: expected 'key value', found {} tokens", toks.len()),
                ));
            }
            match toks[0].to_ascii_lowercase().as_str() {
                "mass" => units.mass = parse_num(toks[1], self.path, *ln, "units mass")?,
                "length" => {
                    let v = parse_num(toks[1], self.path, *ln, "units length")?;
                    if v <= 0.0 {
                        return Err(self.err(*ln, "units length must be positive"));
                    }
                    units.length = v;
                }
                "angle" => {
                    units.degrees = match toks[1].to_ascii_lowercase().as_str() {
                        "deg" | "degree" | "degrees" => true,
                        "rad" | "radian" | "radians" => false,
                        other => return Err(self.err(*ln, format!("unknown angle unit '{other}'"))),
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn root(&self, lines: &Lines) -> Result<AsfRoot, PoseError> {
        let mut root = AsfRoot {
            order: vec![Dof::Tx, Dof::Ty, Dof::Tz, Dof::Rx, Dof::Ry, Dof::Rz],
            axis: [Axis::X, Axis::Y, Axis::Z],
            position: DVec3::ZERO,
            orientation: DVec3::ZERO,
        };
        for (ln, toks) in lines {
            let rest = &toks[1..];
            match toks[0].to_ascii_lowercase().as_str() {
                "order" => {
                    root.order = rest
                        .iter()
                        .map(|t| Dof::parse(t).filter(|d| *d != Dof::L))
                        .collect::<Option<Vec<_>>>()
                        .ok_or_else(|| {
                            self.err(
                                *ln,
                                format!("root order: unknown channel in '{}'", rest.join(" ")),
                            )
                        })?;
                }
                "axis" => {
                    root.axis = rest
                        .first()
                        .and_then(|s| Axis::parse_order(s))
                        .filter(|_| rest.len() == 1)
                        .ok_or_else(|| self.err(*ln, "root axis: expected an order such as XYZ"))?;
                }
                "position" => {
                    root.position = parse_array::<3>(rest, self.path, *ln, "root position")?.into()
                }
                "orientation" => {
                    root.orientation =
                        parse_array::<3>(rest, self.path, *ln, "root orientation")?.into()
                }
                _ => {}
            }
        }
        Ok(root)
    }

    /// Parses `begin ... end` bone blocks from line index `i`; returns them and the index
    /// of the next section's line.
    fn bonedata(&self, mut i: usize) -> Result<(Vec<RawBone>, usize), PoseError> {
        let mut bones = Vec::new();
        while i < self.lines.len() {
            let (ln, toks) = &self.lines[i];
            if toks[0].starts_with(':') {
                break;
            }
            if !toks[0].eq_ignore_ascii_case("begin") {
                return Err(self.err(
                    *ln,
                    format!("bonedata: expected 'begin', found '{}'", toks[0]),
                ));
            }
            let (bone, next) = self.bone(*ln, i + 1)?;
            bones.push(bone);
            i = next;
        }
        Ok((bones, i))
    }

    fn bone(&self, begin: usize, mut i: usize) -> Result<(RawBone, usize), PoseError> {
        let mut bone = RawBone {
            line: begin,
            id: None,
            name: None,
            direction: None,
            length: None,
            axis: DVec3::ZERO,
            axis_order: [Axis::X, Axis::Y, Axis::Z],
            dofs: Vec::new(),
            limits: Vec::new(),
            limits_line: begin,
        };
        loop {
            let Some((ln, toks)) = self.lines.get(i) else {
                return Err(self.err(
                    self.last_line,
                    format!(
                        "file ends inside the bone block begun at line {begin} (truncated file?)"
                    ),
                ));
            };
            let ln = *ln;
            let rest = &toks[1..];
            i += 1;
            match toks[0].to_ascii_lowercase().as_str() {
                "end" => break,
                "begin" => {
                    return Err(self.err(
                        ln,
                        format!("'begin' inside the bone block begun at line {begin}"),
                    ))
                }
                k if k.starts_with(':') => {
                    return Err(self.err(
                        ln,
                        format!("section {k} inside the bone block begun at line {begin}"),
                    ))
                }
                "id" => {
                    let v = parse_array::<1>(rest, self.path, ln, "id")?[0];
                    bone.id = Some(v as i64);
                }
                "name" => {
                    if rest.len() != 1 {
                        return Err(self.err(ln, "name: expected one word"));
                    }
                    bone.name = Some(rest[0].to_string());
                }
                "direction" => {
                    bone.direction =
                        Some(parse_array::<3>(rest, self.path, ln, "direction")?.into())
                }
                "length" => {
                    let v = parse_array::<1>(rest, self.path, ln, "length")?[0];
                    if v < 0.0 {
                        return Err(self.err(ln, "length: negative"));
                    }
                    bone.length = Some(v);
                }
                "axis" => {
                    if rest.len() != 4 {
                        return Err(self.err(
                            ln,
                            format!(
                                "axis: expected 3 angles and an order, found {} values",
                                rest.len()
                            ),
                        ));
                    }
                    bone.axis = parse_array::<3>(&rest[..3], self.path, ln, "axis")?.into();
                    bone.axis_order = Axis::parse_order(rest[3]).ok_or_else(|| {
                        self.err(ln, format!("axis: bad rotation order '{}'", rest[3]))
                    })?;
                }
                "dof" => {
                    bone.dofs = rest
                        .iter()
                        .map(|t| {
                            Dof::parse(t).ok_or_else(|| {
                                self.err(ln, format!("dof: unknown degree of freedom '{t}'"))
                            })
                        })
                        .collect::<Result<_, _>>()?;
                }
                "limits" => {
                    bone.limits_line = ln;
                    self.limit_values(rest, ln, &mut bone.limits)?;
                    while let Some((l2, t2)) = self.lines.get(i) {
                        if !t2[0].starts_with('(') {
                            break;
                        }
                        self.limit_values(t2, *l2, &mut bone.limits)?;
                        i += 1;
                    }
                }
                _ => {}
            }
        }
        Ok((bone, i))
    }

    fn limit_values(&self, toks: &[&str], ln: usize, out: &mut Vec<f64>) -> Result<(), PoseError> {
        for t in toks {
            let t = t.trim_matches(|c| c == '(' || c == ')');
            if t.is_empty() {
                continue;
            }
            out.push(match t.to_ascii_lowercase().as_str() {
                "inf" | "+inf" => f64::INFINITY,
                "-inf" => f64::NEG_INFINITY,
                _ => parse_num(t, self.path, ln, "limits")?,
            });
        }
        Ok(())
    }

    /// Parses `:hierarchy`'s `begin ... end`; returns its lines and the next index.
    #[allow(clippy::type_complexity)]
    fn hierarchy(
        &self,
        header: usize,
        mut i: usize,
    ) -> Result<(Vec<(usize, Vec<&'a str>)>, usize), PoseError> {
        let mut out = Vec::new();
        let mut begun = false;
        loop {
            let Some((ln, toks)) = self.lines.get(i) else {
                return Err(self.err(
                    self.last_line,
                    format!("file ends inside :hierarchy begun at line {header} (truncated file?)"),
                ));
            };
            i += 1;
            let key = toks[0].to_ascii_lowercase();
            if !begun {
                if key != "begin" {
                    return Err(self.err(
                        *ln,
                        format!("hierarchy: expected 'begin', found '{}'", toks[0]),
                    ));
                }
                begun = true;
            } else if key == "end" {
                return Ok((out, i));
            } else if key.starts_with(':') {
                return Err(self.err(*ln, format!("hierarchy: missing 'end' before {}", toks[0])));
            } else {
                out.push((*ln, toks.clone()));
            }
        }
    }

    fn finish(
        &self,
        name: String,
        units: AsfUnits,
        mut root: AsfRoot,
        raw: Vec<RawBone>,
        hierarchy: Vec<(usize, Vec<&str>)>,
    ) -> Result<Asf, PoseError> {
        let to_rad = if units.degrees {
            std::f64::consts::PI / 180.0
        } else {
            1.0
        };
        root.orientation *= to_rad;
        let mut bones: Vec<AsfBone> = Vec::with_capacity(raw.len());
        for r in raw {
            let name = r
                .name
                .ok_or_else(|| self.err(r.line, "bone block without 'name'"))?;
            if name == "root" || bones.iter().any(|b| b.name == name) {
                return Err(self.err(r.line, format!("bone '{name}' defined twice")));
            }
            let length = r
                .length
                .ok_or_else(|| self.err(r.line, format!("bone '{name}' has no 'length'")))?;
            let dir = r
                .direction
                .ok_or_else(|| self.err(r.line, format!("bone '{name}' has no 'direction'")))?;
            let direction = if dir.length() > 1e-12 {
                dir.normalize()
            } else if length == 0.0 {
                DVec3::ZERO
            } else {
                return Err(self.err(r.line, format!("bone '{name}' has a zero direction")));
            };
            if !r.limits.is_empty() && r.limits.len() != 2 * r.dofs.len() {
                return Err(self.err(
                    r.limits_line,
                    format!(
                        "bone '{name}': {} limit values for {} dofs (expected {})",
                        r.limits.len(),
                        r.dofs.len(),
                        2 * r.dofs.len()
                    ),
                ));
            }
            let limits = r
                .limits
                .chunks(2)
                .zip(&r.dofs)
                .map(|(c, d)| {
                    let s = if d.rotation_axis().is_some() {
                        to_rad
                    } else {
                        1.0
                    };
                    (c[0] * s, c[1] * s)
                })
                .collect();
            bones.push(AsfBone {
                id: r.id,
                name,
                direction,
                length,
                axis: r.axis * to_rad,
                axis_order: r.axis_order,
                dofs: r.dofs,
                limits,
                parent: None,
            });
        }
        // Parents from the hierarchy: usize::MAX marks "child of the root".
        let mut parent: Vec<Option<usize>> = vec![None; bones.len()];
        let find = |n: &str| bones.iter().position(|b| b.name == n);
        for (ln, toks) in &hierarchy {
            let p = if toks[0] == "root" {
                usize::MAX
            } else {
                find(toks[0]).ok_or_else(|| {
                    self.err(
                        *ln,
                        format!(
                            "hierarchy: bone '{}' was never defined in :bonedata",
                            toks[0]
                        ),
                    )
                })?
            };
            for c in &toks[1..] {
                let ci = find(c).ok_or_else(|| {
                    self.err(
                        *ln,
                        format!("hierarchy: bone '{c}' was never defined in :bonedata"),
                    )
                })?;
                if parent[ci].is_some() {
                    return Err(self.err(*ln, format!("hierarchy: bone '{c}' has two parents")));
                }
                parent[ci] = Some(p);
            }
        }
        let hier_line = hierarchy.last().map_or(self.last_line, |h| h.0);
        for (i, p) in parent.iter().enumerate() {
            match p {
                None => {
                    return Err(self.err(
                        hier_line,
                        format!("bone '{}' does not appear in :hierarchy", bones[i].name),
                    ))
                }
                Some(p) => bones[i].parent = (*p != usize::MAX).then_some(*p),
            }
        }
        // Parents-first order, breadth first from the root's children.
        let mut order: Vec<usize> = (0..bones.len())
            .filter(|&i| bones[i].parent.is_none())
            .collect();
        let mut k = 0;
        while k < order.len() {
            let p = order[k];
            order.extend((0..bones.len()).filter(|&i| bones[i].parent == Some(p)));
            k += 1;
        }
        if order.len() != bones.len() {
            let lost = (0..bones.len()).find(|i| !order.contains(i)).unwrap_or(0);
            return Err(self.err(
                hier_line,
                format!(
                    "hierarchy: bone '{}' is not connected to the root (cycle)",
                    bones[lost].name
                ),
            ));
        }
        Ok(Asf {
            path: self.path.to_path_buf(),
            name,
            units,
            root,
            bones,
            order,
        })
    }
}
