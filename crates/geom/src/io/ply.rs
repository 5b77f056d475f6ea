//! Stanford PLY reading (ASCII, binary little and big endian) and writing (binary little
//! endian).
//!
//! Reading keeps the `x y z` properties of the `vertex` element (any numeric type) and the
//! `vertex_indices` (or `vertex_index`) list of the `face` element (integer count and index
//! types), fan-triangulating polygons. Other properties and elements are parsed and skipped.
//! Element counts must match the data exactly: missing or trailing data is an error.

use std::io::Write;
use std::path::Path;

use glam::Vec3;

use super::atomic::write_atomic;
use crate::error::{GeomError, Result};
use crate::mesh::TriMesh;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Clone, Debug)]
enum Prop {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: u64,
    props: Vec<(String, Prop)>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    BinaryLe,
    BinaryBe,
}

struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Byte offset of the first data byte.
    data_start: usize,
    /// Number of header lines (data line numbers continue after it).
    lines: usize,
}

fn parse_header(bytes: &[u8], path: &Path) -> Result<Header> {
    let mut pos = 0usize;
    let mut line_no = 0usize;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        line_no += 1;
        let rest = &bytes[pos..];
        let Some(nl) = rest.iter().position(|&b| b == b'\n') else {
            return Err(GeomError::text(
                path,
                line_no,
                "header ends before end_header",
            ));
        };
        let raw = &rest[..nl];
        pos += nl + 1;
        let text = std::str::from_utf8(raw)
            .map_err(|_| GeomError::text(path, line_no, "header line is not text"))?
            .trim_end_matches('\r');
        let toks: Vec<&str> = text.split_ascii_whitespace().collect();
        let err = |msg: String| GeomError::text(path, line_no, msg);
        if line_no == 1 {
            if text.trim() != "ply" {
                return Err(err("not a PLY file (first line must be \"ply\")".into()));
            }
            continue;
        }
        match toks.first().copied() {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                format = Some(match toks.get(1).copied() {
                    Some("ascii") => Format::Ascii,
                    Some("binary_little_endian") => Format::BinaryLe,
                    Some("binary_big_endian") => Format::BinaryBe,
                    other => return Err(err(format!("unknown format {other:?}"))),
                });
            }
            Some("element") => {
                let (Some(name), Some(count), None) = (toks.get(1), toks.get(2), toks.get(3))
                else {
                    return Err(err("expected \"element NAME COUNT\"".into()));
                };
                let count: u64 = count
                    .parse()
                    .map_err(|_| err(format!("bad element count {count:?}")))?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                });
            }
            Some("property") => {
                let Some(el) = elements.last_mut() else {
                    return Err(err("property before any element".into()));
                };
                let ty = |s: Option<&&str>| {
                    s.and_then(|s| Scalar::parse(s))
                        .ok_or_else(|| err(format!("unknown property type {s:?}")))
                };
                let (prop, name) = if toks.get(1) == Some(&"list") {
                    let (count, item) = (ty(toks.get(2))?, ty(toks.get(3))?);
                    if count.is_float() {
                        return Err(err("list count type must be an integer".into()));
                    }
                    (Prop::List { count, item }, toks.get(4))
                } else {
                    (Prop::Scalar(ty(toks.get(1))?), toks.get(2))
                };
                let Some(name) = name else {
                    return Err(err("property without a name".into()));
                };
                el.props.push((name.to_string(), prop));
            }
            Some("end_header") => break,
            Some(other) => return Err(err(format!("unknown header keyword {other:?}"))),
        }
    }
    let format =
        format.ok_or_else(|| GeomError::text(path, line_no, "header has no format line"))?;
    Ok(Header {
        format,
        elements,
        data_start: pos,
        lines: line_no,
    })
}

/// Where the vertex and face data of interest sit in the element list.
struct Layout {
    /// Property indices of x, y, z in the vertex element.
    xyz: [usize; 3],
    /// Property index of the face index list.
    face_list: Option<usize>,
    num_vertices: u64,
}

fn layout(h: &Header, path: &Path) -> Result<Layout> {
    let herr = |msg: String| GeomError::text(path, h.lines, msg);
    let v = h
        .elements
        .iter()
        .find(|e| e.name == "vertex")
        .ok_or_else(|| herr("header declares no vertex element".into()))?;
    let find = |name: &str| -> Result<usize> {
        match v.props.iter().position(|(n, _)| n == name) {
            Some(i) if matches!(v.props[i].1, Prop::Scalar(_)) => Ok(i),
            _ => Err(herr(format!(
                "vertex element has no scalar property {name:?}"
            ))),
        }
    };
    let xyz = [find("x")?, find("y")?, find("z")?];
    if v.count > u32::MAX as u64 {
        return Err(herr(format!("{} vertices do not fit u32 indices", v.count)));
    }
    let mut face_list = None;
    if let Some(f) = h.elements.iter().find(|e| e.name == "face") {
        let i = f
            .props
            .iter()
            .position(|(n, _)| n == "vertex_indices" || n == "vertex_index")
            .ok_or_else(|| herr("face element has no vertex_indices list".into()))?;
        match f.props[i].1 {
            Prop::List { item, .. } if !item.is_float() => face_list = Some(i),
            _ => return Err(herr("vertex_indices must be a list of integers".into())),
        }
    }
    Ok(Layout {
        xyz,
        face_list,
        num_vertices: v.count,
    })
}

/// A source of values: ASCII tokens or binary scalars. Errors carry the position.
trait Source {
    fn scalar(&mut self, s: Scalar) -> Result<f64>;
    fn error(&self, msg: String) -> GeomError;
    fn finish(&mut self) -> Result<()>;
}

struct Binary<'a> {
    bytes: &'a [u8],
    pos: usize,
    big: bool,
    path: &'a Path,
}

impl Source for Binary<'_> {
    fn scalar(&mut self, s: Scalar) -> Result<f64> {
        let n = s.size();
        let Some(b) = self.bytes.get(self.pos..self.pos + n) else {
            return Err(self.error(format!(
                "unexpected end of data ({} bytes left, {n} needed)",
                self.bytes.len() - self.pos
            )));
        };
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.big {
            a[..n].reverse();
        }
        self.pos += n;
        Ok(match s {
            Scalar::I8 => a[0] as i8 as f64,
            Scalar::U8 => a[0] as f64,
            Scalar::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(a),
        })
    }

    fn error(&self, msg: String) -> GeomError {
        GeomError::binary(self.path, self.pos as u64, msg)
    }

    fn finish(&mut self) -> Result<()> {
        if self.pos != self.bytes.len() {
            return Err(self.error(format!(
                "{} bytes of data after the last declared element (header counts too small?)",
                self.bytes.len() - self.pos
            )));
        }
        Ok(())
    }
}

struct Ascii<'a> {
    lines: std::iter::Enumerate<std::str::Split<'a, char>>,
    toks: std::str::SplitAsciiWhitespace<'a>,
    line: usize,
    first_line: usize,
    path: &'a Path,
}

impl<'a> Ascii<'a> {
    fn next_token(&mut self) -> Option<&'a str> {
        loop {
            if let Some(t) = self.toks.next() {
                return Some(t);
            }
            let (i, l) = self.lines.next()?;
            self.toks = l.split_ascii_whitespace();
            if !l.trim_ascii().is_empty() {
                // Blank lines do not move the reported position (EOF is reported at the last
                // line holding data).
                self.line = self.first_line + i;
            }
        }
    }
}

impl Source for Ascii<'_> {
    fn scalar(&mut self, s: Scalar) -> Result<f64> {
        let Some(t) = self.next_token() else {
            return Err(self.error("unexpected end of file (header counts too large?)".into()));
        };
        let v: f64 = if s.is_float() {
            t.parse()
                .map_err(|_| self.error(format!("{t:?} is not a number")))?
        } else {
            t.parse::<i64>()
                .map_err(|_| self.error(format!("{t:?} is not an integer")))? as f64
        };
        Ok(v)
    }

    fn error(&self, msg: String) -> GeomError {
        GeomError::text(self.path, self.line, msg)
    }

    fn finish(&mut self) -> Result<()> {
        if let Some(t) = self.next_token() {
            return Err(self.error(format!(
                "data {t:?} after the last declared element (header counts too small?)"
            )));
        }
        Ok(())
    }
}

fn read_body(h: &Header, lay: &Layout, src: &mut dyn Source, data_len: usize) -> Result<TriMesh> {
    let mut mesh = TriMesh::default();
    let mut poly: Vec<u32> = Vec::new();
    for el in &h.elements {
        // Each element takes at least one byte, which bounds what a lying header can reserve.
        let cap = el.count.min(data_len as u64) as usize;
        if el.props.is_empty() {
            continue; // takes no bytes whatever its count
        }
        let is_vertex = el.name == "vertex";
        let is_face = el.name == "face";
        if is_vertex {
            mesh.vertices.reserve(cap);
        } else if is_face {
            mesh.faces.reserve(cap);
        }
        for ei in 0..el.count {
            let mut xyz = [0f32; 3];
            for (pi, (pname, prop)) in el.props.iter().enumerate() {
                match *prop {
                    Prop::Scalar(s) => {
                        let v = src.scalar(s)?;
                        if is_vertex {
                            if let Some(k) = lay.xyz.iter().position(|&x| x == pi) {
                                let f = v as f32;
                                if !f.is_finite() {
                                    return Err(src.error(format!(
                                        "vertex {ei}: {pname} = {v} is not a finite f32"
                                    )));
                                }
                                xyz[k] = f;
                            }
                        }
                    }
                    Prop::List { count, item } => {
                        let n = src.scalar(count)?;
                        if n < 0.0 {
                            return Err(
                                src.error(format!("{} {ei}: negative list length", el.name))
                            );
                        }
                        let keep = is_face && lay.face_list == Some(pi);
                        poly.clear();
                        for _ in 0..n as u64 {
                            let v = src.scalar(item)?;
                            if keep {
                                if v < 0.0 || v >= lay.num_vertices as f64 {
                                    return Err(src.error(format!(
                                        "face {ei}: vertex index {v} out of range ({} vertices)",
                                        lay.num_vertices
                                    )));
                                }
                                poly.push(v as u32);
                            }
                        }
                        if keep {
                            if poly.len() < 3 {
                                return Err(src.error(format!(
                                    "face {ei} has {} vertices (at least 3 needed)",
                                    poly.len()
                                )));
                            }
                            for i in 1..poly.len() - 1 {
                                mesh.faces.push([poly[0], poly[i], poly[i + 1]]);
                            }
                        }
                    }
                }
            }
            if is_vertex {
                mesh.vertices.push(Vec3::from_array(xyz));
            }
        }
    }
    src.finish()?;
    Ok(mesh)
}

/// Parses PLY bytes; `path` is only used in error messages.
pub fn parse_ply(bytes: &[u8], path: &Path) -> Result<TriMesh> {
    let h = parse_header(bytes, path)?;
    let lay = layout(&h, path)?;
    let data = &bytes[h.data_start..];
    match h.format {
        Format::Ascii => {
            let text = std::str::from_utf8(data).map_err(|e| {
                GeomError::binary(
                    path,
                    (h.data_start + e.valid_up_to()) as u64,
                    "ASCII PLY data is not text",
                )
            })?;
            let mut src = Ascii {
                lines: text.split('\n').enumerate(),
                toks: "".split_ascii_whitespace(),
                line: h.lines,
                first_line: h.lines + 1,
                path,
            };
            read_body(&h, &lay, &mut src, data.len())
        }
        Format::BinaryLe | Format::BinaryBe => {
            let mut src = Binary {
                bytes,
                pos: h.data_start,
                big: h.format == Format::BinaryBe,
                path,
            };
            read_body(&h, &lay, &mut src, data.len())
        }
    }
}

/// Reads a PLY file (ASCII or binary) into a triangle mesh.
pub fn read_ply(path: impl AsRef<Path>) -> Result<TriMesh> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| GeomError::io(path, e))?;
    parse_ply(&bytes, path)
}

/// Encodes `mesh` as binary little-endian PLY (`float x y z`, `list uchar int vertex_indices`).
pub fn encode_ply(mesh: &TriMesh) -> Result<Vec<u8>> {
    mesh.validate()?;
    if mesh.vertices.len() > i32::MAX as usize {
        return Err(GeomError::InvalidMesh(
            "too many vertices for PLY int indices".into(),
        ));
    }
    let mut out = Vec::with_capacity(200 + mesh.vertices.len() * 12 + mesh.faces.len() * 13);
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\ncomment garnet geom\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        mesh.vertices.len(),
        mesh.faces.len()
    )
    .map_err(|e| GeomError::InvalidInput(e.to_string()))?;
    for v in &mesh.vertices {
        for c in v.to_array() {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for f in &mesh.faces {
        out.push(3);
        for &i in f {
            out.extend_from_slice(&(i as i32).to_le_bytes());
        }
    }
    Ok(out)
}

/// Writes `mesh` as binary little-endian PLY, atomically. Fails if the mesh does not validate.
pub fn write_ply(path: impl AsRef<Path>, mesh: &TriMesh) -> Result<()> {
    let bytes = encode_ply(mesh)?;
    write_atomic(path, |w| w.write_all(&bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p() -> &'static Path {
        Path::new("t.ply")
    }

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment hi\nelement vertex 4\nproperty double x\n\
        property float y\nproperty uchar red\nproperty float z\nelement face 1\n\
        property list uchar uint vertex_indices\nelement edge 1\nproperty int a\nproperty int b\n\
        end_header\n0 0 255 0\n1 0 0 0\n1 1 0 0\n0 1 0 0\n4 0 1 2 3\n0 1\n";

    #[test]
    fn ascii_quad() {
        let m = parse_ply(ASCII.as_bytes(), p()).unwrap();
        assert_eq!(m.vertices[2], Vec3::new(1., 1., 0.));
        assert_eq!(m.faces, vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn ascii_errors() {
        let more = ASCII.replace("element vertex 4", "element vertex 5");
        let e = parse_ply(more.as_bytes(), p()).unwrap_err().to_string();
        assert!(e.contains("t.ply:20:") && e.contains("end of file"), "{e}");
        let fewer = ASCII.replace("element face 1", "element face 0");
        let e = parse_ply(fewer.as_bytes(), p()).unwrap_err().to_string();
        assert!(
            e.contains("t.ply:19:") && e.contains("after the last"),
            "{e}"
        );
        let bad = ASCII.replace("1 1 0 0", "1 z 0 0");
        let e = parse_ply(bad.as_bytes(), p()).unwrap_err().to_string();
        assert!(e.contains("t.ply:17:") && e.contains("\"z\""), "{e}");
        let e = parse_ply(
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n",
            p(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("\"y\""), "{e}");
        let e = parse_ply(b"plx\n", p()).unwrap_err().to_string();
        assert!(e.contains("t.ply:1:"), "{e}");
        let e = parse_ply(b"ply\nformat ascii 1.0\nelement vertex 1\n", p()).unwrap_err();
        assert!(e.to_string().contains("end_header"));
    }

    #[test]
    fn binary_round_trip_and_truncation() {
        let m = TriMesh::icosphere(1, 0.3);
        let bytes = encode_ply(&m).unwrap();
        assert_eq!(parse_ply(&bytes, p()).unwrap(), m);
        let cut = &bytes[..bytes.len() - 5];
        let e = parse_ply(cut, p()).unwrap_err().to_string();
        assert!(
            e.contains("t.ply: byte") && e.contains("end of data"),
            "{e}"
        );
        let mut extra = bytes.clone();
        extra.push(0);
        assert!(parse_ply(&extra, p()).is_err());
    }

    #[test]
    fn big_endian_and_huge_count() {
        let mut b = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\n\
            property float y\nproperty float z\nelement face 1\nproperty list uchar ushort vertex_index\n\
            end_header\n"
            .to_vec();
        for v in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
            b.extend_from_slice(&v.to_be_bytes());
        }
        b.push(3);
        for i in [0u16, 1, 2] {
            b.extend_from_slice(&i.to_be_bytes());
        }
        let m = parse_ply(&b, p()).unwrap();
        assert_eq!(m.faces, vec![[0, 1, 2]]);
        assert_eq!(m.vertices[1], Vec3::X);
        let huge = String::from_utf8_lossy(&b).replace("vertex 3", "vertex 4000000000");
        assert!(parse_ply(huge.as_bytes(), p()).is_err());
    }
}
