//! Wavefront OBJ reading and writing.
//!
//! Reading keeps `v` (first three numbers; extra vertex colour values are ignored), `vt`, `f`
//! (forms `a`, `a/b`, `a/b/c`, `a//c`, negative relative indices; polygons fan-triangulated)
//! and `g` group names; `vn`, `o`, `s`, `usemtl`, `mtllib`, `l`, `p`, free-form geometry
//! statements and `#` comments are ignored. Anything else is an error naming the line.

use std::io::Write;
use std::ops::Range;
use std::path::Path;

use glam::{Vec2, Vec3};

use super::atomic::write_atomic;
use crate::error::{GeomError, Result};
use crate::mesh::TriMesh;

/// A named group of an OBJ file (`g name`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ObjGroup {
    /// Group name (several names on one `g` line are joined with a space).
    pub name: String,
    /// The triangles of [`ObjData::mesh`] read while this group was current.
    pub faces: Range<usize>,
}

/// Everything [`read_obj_data`] keeps from an OBJ file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjData {
    /// Positions `[N]` and triangles `[F]` (polygons fan-triangulated, 0-based).
    pub mesh: TriMesh,
    /// `[T]` texture coordinates `(u, v)` in file order.
    pub texcoords: Vec<Vec2>,
    /// `[F]` texture-coordinate indices of each triangle corner; `Some` only when every face
    /// corner in the file names one.
    pub face_texcoords: Option<Vec<[u32; 3]>>,
    /// Groups in file order; faces before the first `g` are in no group.
    pub groups: Vec<ObjGroup>,
}

/// Statements that are valid OBJ but carry nothing we use.
const IGNORED: &[&str] = &[
    "vn",
    "vp",
    "o",
    "s",
    "usemtl",
    "mtllib",
    "l",
    "p",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "mg",
    "bevel",
    "c_interp",
    "d_interp",
    "lod",
    "maplib",
    "usemap",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
];

/// Reads the triangle mesh of an OBJ file (see [`read_obj_data`] for texture coordinates and
/// groups).
pub fn read_obj(path: impl AsRef<Path>) -> Result<TriMesh> {
    Ok(read_obj_data(path)?.mesh)
}

/// Reads an OBJ file: positions, faces, texture coordinates and groups.
pub fn read_obj_data(path: impl AsRef<Path>) -> Result<ObjData> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| GeomError::io(path, e))?;
    parse_obj(&String::from_utf8_lossy(&bytes), path)
}

fn parse_f32(tok: Option<&str>, what: &str, path: &Path, line: usize) -> Result<f32> {
    let tok = tok.ok_or_else(|| GeomError::text(path, line, format!("missing {what}")))?;
    let x: f32 = tok
        .parse()
        .map_err(|_| GeomError::text(path, line, format!("{what} {tok:?} is not a number")))?;
    if !x.is_finite() {
        return Err(GeomError::text(
            path,
            line,
            format!("{what} {tok:?} is not finite"),
        ));
    }
    Ok(x)
}

/// Resolves a 1-based or negative OBJ index against the `count` elements defined so far.
/// Positive indices may point forward (checked at the end of the file).
fn resolve(tok: &str, count: usize, what: &str, path: &Path, line: usize) -> Result<u32> {
    let i: i64 = tok.parse().map_err(|_| {
        GeomError::text(
            path,
            line,
            format!("{what} index {tok:?} is not an integer"),
        )
    })?;
    let r = if i > 0 {
        i - 1
    } else if i < 0 {
        count as i64 + i
    } else {
        return Err(GeomError::text(
            path,
            line,
            format!("{what} index 0 (OBJ indices start at 1)"),
        ));
    };
    if r < 0 || r >= u32::MAX as i64 {
        return Err(GeomError::text(
            path,
            line,
            format!("{what} index {i} out of range ({count} defined so far)"),
        ));
    }
    Ok(r as u32)
}

/// Parses OBJ text; `path` is only used in error messages.
pub fn parse_obj(text: &str, path: &Path) -> Result<ObjData> {
    let mut out = ObjData::default();
    let mut all_textured = true;
    let mut tex_faces: Vec<[u32; 3]> = Vec::new();
    // (line, largest 0-based position index, largest texcoord index) of each polygon, to check
    // forward references once the whole file is read.
    let mut max_refs: Vec<(usize, u32, Option<u32>)> = Vec::new();
    let mut poly: Vec<u32> = Vec::new();
    let mut poly_t: Vec<u32> = Vec::new();
    for (li, raw) in text.split('\n').enumerate() {
        let line = li + 1;
        let content = raw.split('#').next().unwrap_or("");
        let mut toks = content.split_ascii_whitespace();
        let Some(key) = toks.next() else { continue };
        match key {
            "v" => {
                let x = parse_f32(toks.next(), "x coordinate", path, line)?;
                let y = parse_f32(toks.next(), "y coordinate", path, line)?;
                let z = parse_f32(toks.next(), "z coordinate", path, line)?;
                for t in toks {
                    parse_f32(Some(t), "vertex value", path, line)?;
                }
                out.mesh.vertices.push(Vec3::new(x, y, z));
            }
            "vt" => {
                let u = parse_f32(toks.next(), "u coordinate", path, line)?;
                let v = match toks.next() {
                    Some(t) => parse_f32(Some(t), "v coordinate", path, line)?,
                    None => 0.0,
                };
                out.texcoords.push(Vec2::new(u, v));
            }
            "f" | "fo" => {
                poly.clear();
                poly_t.clear();
                let mut textured = true;
                for tok in toks {
                    let mut parts = tok.split('/');
                    let vtok = parts.next().unwrap_or("");
                    if vtok.is_empty() {
                        return Err(GeomError::text(
                            path,
                            line,
                            format!("face vertex {tok:?} has no position index"),
                        ));
                    }
                    poly.push(resolve(
                        vtok,
                        out.mesh.vertices.len(),
                        "vertex",
                        path,
                        line,
                    )?);
                    match parts.next() {
                        Some(t) if !t.is_empty() => {
                            poly_t.push(resolve(t, out.texcoords.len(), "texcoord", path, line)?)
                        }
                        _ => textured = false,
                    }
                    if let Some(n) = parts.next() {
                        if !n.is_empty() {
                            // Normal indices are ignored but must be well-formed.
                            n.parse::<i64>().map_err(|_| {
                                GeomError::text(
                                    path,
                                    line,
                                    format!("normal index {n:?} is not an integer"),
                                )
                            })?;
                        }
                    }
                    if parts.next().is_some() {
                        return Err(GeomError::text(
                            path,
                            line,
                            format!("face vertex {tok:?} has more than three indices"),
                        ));
                    }
                }
                if poly.len() < 3 {
                    return Err(GeomError::text(
                        path,
                        line,
                        format!("face with {} vertices (at least 3 needed)", poly.len()),
                    ));
                }
                all_textured &= textured;
                let max_v = poly.iter().copied().max().unwrap_or(0);
                let max_t = if textured {
                    poly_t.iter().copied().max()
                } else {
                    None
                };
                max_refs.push((line, max_v, max_t));
                for i in 1..poly.len() - 1 {
                    out.mesh.faces.push([poly[0], poly[i], poly[i + 1]]);
                    if textured {
                        tex_faces.push([poly_t[0], poly_t[i], poly_t[i + 1]]);
                    }
                }
            }
            "g" => {
                let nfaces = out.mesh.faces.len();
                if let Some(last) = out.groups.last_mut() {
                    last.faces.end = nfaces;
                }
                let name = toks.collect::<Vec<_>>().join(" ");
                out.groups.push(ObjGroup {
                    name,
                    faces: nfaces..nfaces,
                });
            }
            k if IGNORED.contains(&k) => {}
            k => {
                return Err(GeomError::text(
                    path,
                    line,
                    format!("unknown statement {k:?}"),
                ));
            }
        }
    }
    if let Some(last) = out.groups.last_mut() {
        last.faces.end = out.mesh.faces.len();
    }
    let (nv, nt) = (out.mesh.vertices.len(), out.texcoords.len());
    for &(line, mv, mt) in &max_refs {
        if mv as usize >= nv {
            return Err(GeomError::text(
                path,
                line,
                format!(
                    "vertex index {} out of range (file has {nv} vertices)",
                    mv as u64 + 1
                ),
            ));
        }
        if let Some(mt) = mt {
            if mt as usize >= nt {
                return Err(GeomError::text(
                    path,
                    line,
                    format!(
                        "texcoord index {} out of range (file has {nt} texcoords)",
                        mt as u64 + 1
                    ),
                ));
            }
        }
    }
    if nv > u32::MAX as usize {
        return Err(GeomError::format(
            path,
            format!("{nv} vertices do not fit u32 indices"),
        ));
    }
    out.face_texcoords = (all_textured && !out.mesh.faces.is_empty()).then_some(tex_faces);
    Ok(out)
}

/// Writes `mesh` as OBJ (`v` lines with round-trip exact floats, 1-based `f` lines),
/// atomically. Fails if the mesh does not validate.
pub fn write_obj(path: impl AsRef<Path>, mesh: &TriMesh) -> Result<()> {
    write_obj_data(
        path,
        &ObjData {
            mesh: mesh.clone(),
            ..Default::default()
        },
    )
}

/// Writes positions, faces, and (when `face_texcoords` is `Some`) texture coordinates and
/// groups of `data` as OBJ, atomically. Fails if the mesh or texcoord indices are invalid.
pub fn write_obj_data(path: impl AsRef<Path>, data: &ObjData) -> Result<()> {
    let path = path.as_ref();
    let mesh = &data.mesh;
    mesh.validate()?;
    let tex = match &data.face_texcoords {
        Some(ft) => {
            if ft.len() != mesh.faces.len() {
                return Err(GeomError::InvalidInput(format!(
                    "{} texcoord faces for {} faces",
                    ft.len(),
                    mesh.faces.len()
                )));
            }
            let nt = data.texcoords.len();
            if ft.iter().flatten().any(|&t| t as usize >= nt) {
                return Err(GeomError::InvalidInput(format!(
                    "texcoord index out of range ({nt} texcoords)"
                )));
            }
            if data.texcoords.iter().any(|t| !t.is_finite()) {
                return Err(GeomError::InvalidInput("non-finite texcoord".into()));
            }
            Some(ft)
        }
        None => None,
    };
    write_atomic(path, |w: &mut dyn Write| {
        writeln!(
            w,
            "# garnet OBJ: {} vertices, {} faces",
            mesh.vertices.len(),
            mesh.faces.len()
        )?;
        for v in &mesh.vertices {
            writeln!(w, "v {} {} {}", v.x, v.y, v.z)?;
        }
        if tex.is_some() {
            for t in &data.texcoords {
                writeln!(w, "vt {} {}", t.x, t.y)?;
            }
        }
        let mut groups = data.groups.iter().peekable();
        for (i, f) in mesh.faces.iter().enumerate() {
            while let Some(g) = groups.peek() {
                if g.faces.start > i {
                    break;
                }
                if g.faces.start == i {
                    writeln!(w, "g {}", g.name)?;
                }
                groups.next();
            }
            match tex {
                Some(ft) => {
                    let t = ft[i];
                    writeln!(
                        w,
                        "f {}/{} {}/{} {}/{}",
                        f[0] + 1,
                        t[0] + 1,
                        f[1] + 1,
                        t[1] + 1,
                        f[2] + 1,
                        t[2] + 1
                    )?
                }
                None => writeln!(w, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1)?,
            }
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p() -> &'static Path {
        Path::new("t.obj")
    }

    #[test]
    fn parses_all_face_forms() {
        let src = "# c\nv 0 0 0\nv 1 0 0\nv 1 1 0 0.5 0.5 0.5\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n\
                   o thing\ng a\ns 1\nusemtl m\nf 1 2 3\nf 1/1 2/2 3/3\nf 1/1/1 2/2/1 3/3/1\n\
                   g b c\nf 1//1 3//1 4//1\nf -4 -3 -2 -1\n";
        let d = parse_obj(src, p()).unwrap();
        assert_eq!(d.mesh.vertices.len(), 4);
        assert_eq!(
            d.mesh.faces,
            vec![
                [0, 1, 2],
                [0, 1, 2],
                [0, 1, 2],
                [0, 2, 3],
                [0, 1, 2],
                [0, 2, 3]
            ]
        );
        assert_eq!(d.texcoords.len(), 3);
        assert!(d.face_texcoords.is_none());
        assert_eq!(d.groups.len(), 2);
        assert_eq!(
            d.groups[0],
            ObjGroup {
                name: "a".into(),
                faces: 0..3
            }
        );
        assert_eq!(
            d.groups[1],
            ObjGroup {
                name: "b c".into(),
                faces: 3..6
            }
        );
    }

    #[test]
    fn crlf_and_forward_reference() {
        let d = parse_obj("f 1 2 3\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\n", p()).unwrap();
        assert_eq!(d.mesh.faces, vec![[0, 1, 2]]);
    }

    #[test]
    fn errors_name_line() {
        let cases = [
            ("v 0 0 0\nv 1 0\n", ":2:", "missing z"),
            ("v 0 0 0\nv 1 x 0\n", ":2:", "not a number"),
            ("v 0 0 nan\n", ":1:", "not finite"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2\n", ":5:", "at least 3"),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
                ":4:",
                "out of range",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n",
                ":4:",
                "out of range",
            ),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", ":4:", "index 0"),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3x\n",
                ":4:",
                "not an integer",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/9 2/9 3/9\n",
                ":4:",
                "texcoord",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 /3\n",
                ":4:",
                "no position",
            ),
            ("v 0 0 0\nbogus 1 2\n", ":2:", "unknown statement"),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n",
                ":4:",
                "integer",
            ),
        ];
        for (src, at, what) in cases {
            let e = parse_obj(src, p()).unwrap_err().to_string();
            assert!(
                e.starts_with("t.obj") && e.contains(at) && e.contains(what),
                "{src:?}: {e}"
            );
        }
    }

    #[test]
    fn textured_round_trip() {
        let d = tempfile::tempdir().unwrap();
        let path = d.path().join("uv.obj");
        let data = ObjData {
            mesh: TriMesh::grid(3, 3, 0.1),
            texcoords: (0..9).map(|i| Vec2::new(i as f32 / 8.0, 0.25)).collect(),
            face_texcoords: None,
            groups: vec![
                ObjGroup {
                    name: "left".into(),
                    faces: 0..4,
                },
                ObjGroup {
                    name: "right".into(),
                    faces: 4..8,
                },
            ],
        };
        let data = ObjData {
            face_texcoords: Some(data.mesh.faces.clone()),
            ..data
        };
        write_obj_data(&path, &data).unwrap();
        assert_eq!(read_obj_data(&path).unwrap(), data);
    }
}
