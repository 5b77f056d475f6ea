//! glTF 2.0 binary (GLB) reading: triangle primitives' positions and indices.
//!
//! Supported: the GLB container with an embedded BIN buffer, float `VEC3` positions,
//! `u8`/`u16`/`u32` indices or none, modes TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN (other
//! modes are skipped), interleaved buffer views (`byteStride`), accessors without a buffer view
//! (zeros), and node transforms (`matrix` or TRS) applied along the default scene's hierarchy.
//! Not supported (an error): external or data-URI buffers, sparse accessors, quantized
//! positions.

use std::path::Path;

use glam::{Mat4, Quat, Vec3};
use serde_json::Value;

use super::glb::{CHUNK_BIN, CHUNK_JSON, GLB_MAGIC};
use crate::error::{GeomError, Result};
use crate::mesh::TriMesh;

/// One triangle primitive read from a GLB file, in world coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct GlbPrimitive {
    /// Index of the glTF mesh holding the primitive.
    pub mesh_index: usize,
    /// Index of the primitive within that mesh.
    pub primitive_index: usize,
    /// The glTF mesh's name, if any.
    pub name: Option<String>,
    /// Positions `[N]` (node transforms applied) and triangles `[F]`.
    pub mesh: TriMesh,
    /// The material's `baseColorFactor` (linear RGBA), if the primitive has a material.
    pub base_color: Option<[f32; 4]>,
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}

/// Splits a GLB file into its JSON document and BIN chunk.
fn container<'a>(bytes: &'a [u8], path: &Path) -> Result<(Value, Option<&'a [u8]>)> {
    let berr = |off: usize, msg: String| GeomError::binary(path, off as u64, msg);
    if bytes.len() < 12 {
        return Err(berr(
            bytes.len(),
            format!("file is {} bytes, a GLB header needs 12", bytes.len()),
        ));
    }
    let magic = u32_at(bytes, 0).unwrap_or(0);
    if magic != GLB_MAGIC {
        return Err(berr(
            0,
            format!(
                "bad magic {:?} (expected \"glTF\")",
                String::from_utf8_lossy(&bytes[..4])
            ),
        ));
    }
    let version = u32_at(bytes, 4).unwrap_or(0);
    if version != 2 {
        return Err(berr(
            4,
            format!("unsupported glTF container version {version}"),
        ));
    }
    let total = u32_at(bytes, 8).unwrap_or(0) as usize;
    if total > bytes.len() {
        return Err(berr(
            8,
            format!(
                "header declares {total} bytes but the file has {}",
                bytes.len()
            ),
        ));
    }
    let bytes = &bytes[..total];
    let mut pos = 12;
    let mut json = None;
    let mut bin = None;
    while pos < bytes.len() {
        let (Some(len), Some(kind)) = (u32_at(bytes, pos), u32_at(bytes, pos + 4)) else {
            return Err(berr(pos, "truncated chunk header".into()));
        };
        let start = pos + 8;
        let end = start
            .checked_add(len as usize)
            .filter(|&e| e <= bytes.len())
            .ok_or_else(|| {
                berr(
                    pos,
                    format!(
                        "chunk of {len} bytes runs past the end of the file ({} bytes)",
                        bytes.len()
                    ),
                )
            })?;
        let data = &bytes[start..end];
        match kind {
            CHUNK_JSON if json.is_none() => {
                if pos != 12 {
                    return Err(berr(pos, "JSON chunk is not the first chunk".into()));
                }
                let doc: Value = serde_json::from_slice(data)
                    .map_err(|e| berr(start, format!("invalid JSON chunk: {e}")))?;
                json = Some(doc);
            }
            CHUNK_BIN if bin.is_none() => bin = Some(data),
            _ => {} // unknown chunk types must be ignored
        }
        pos = end;
    }
    let json = json.ok_or_else(|| berr(12, "no JSON chunk".into()))?;
    Ok((json, bin))
}

struct Doc<'a> {
    json: Value,
    bin: Option<&'a [u8]>,
    path: &'a Path,
}

fn idx(v: &Value, key: &str) -> Option<usize> {
    v.get(key)?.as_u64().map(|x| x as usize)
}

impl Doc<'_> {
    fn err(&self, msg: String) -> GeomError {
        GeomError::format(self.path, msg)
    }

    fn item(&self, list: &str, i: usize) -> Result<&Value> {
        self.json
            .get(list)
            .and_then(|l| l.get(i))
            .ok_or_else(|| self.err(format!("{list}[{i}] does not exist")))
    }

    fn buffer(&self, i: usize) -> Result<&[u8]> {
        let b = self.item("buffers", i)?;
        if i != 0 || b.get("uri").is_some() {
            return Err(self.err(format!(
                "buffers[{i}]: only the embedded GLB buffer is supported"
            )));
        }
        let bin = self
            .bin
            .ok_or_else(|| self.err("buffers[0] but no BIN chunk".into()))?;
        let len =
            idx(b, "byteLength").ok_or_else(|| self.err("buffers[0] has no byteLength".into()))?;
        bin.get(..len).ok_or_else(|| {
            self.err(format!(
                "buffers[0] byteLength {len} exceeds the BIN chunk ({} bytes)",
                bin.len()
            ))
        })
    }

    /// Reads accessor `a` as `count` rows of `comps` components converted to f64,
    /// checking type, component types and bounds.
    fn accessor(&self, a: usize, want_type: &str, allowed: &[u64]) -> Result<Vec<f64>> {
        let acc = self.item("accessors", a)?;
        let e = |m: &str| self.err(format!("accessors[{a}]: {m}"));
        if acc.get("sparse").is_some() {
            return Err(e("sparse accessors are not supported"));
        }
        let ty = acc.get("type").and_then(Value::as_str).unwrap_or("");
        if ty != want_type {
            return Err(e(&format!("type {ty:?}, expected {want_type:?}")));
        }
        let comps = if ty == "VEC3" { 3 } else { 1 };
        let ct = acc
            .get("componentType")
            .and_then(Value::as_u64)
            .unwrap_or(0);
        if !allowed.contains(&ct) {
            return Err(e(&format!("componentType {ct} not supported here")));
        }
        let csize = match ct {
            5120 | 5121 => 1,
            5122 | 5123 => 2,
            _ => 4,
        };
        let count = idx(acc, "count").ok_or_else(|| e("no count"))?;
        let Some(view_i) = idx(acc, "bufferView") else {
            // No buffer view: all zeros (rare; bounded so a bogus count cannot exhaust memory).
            if count > 1 << 24 {
                return Err(e(&format!(
                    "count {count} without a buffer view is implausible"
                )));
            }
            return Ok(vec![0.0; count * comps]);
        };
        let view = self.item("bufferViews", view_i)?;
        let buf = self.buffer(idx(view, "buffer").unwrap_or(usize::MAX))?;
        let voff = idx(view, "byteOffset").unwrap_or(0);
        let vlen = idx(view, "byteLength").ok_or_else(|| e("buffer view has no byteLength"))?;
        let vdata = voff
            .checked_add(vlen)
            .and_then(|end| buf.get(voff..end))
            .ok_or_else(|| e(&format!("bufferViews[{view_i}] runs past its buffer")))?;
        let elem = csize * comps;
        let stride = idx(view, "byteStride").unwrap_or(elem);
        if stride < elem {
            return Err(e(&format!(
                "byteStride {stride} smaller than the element ({elem} bytes)"
            )));
        }
        let aoff = idx(acc, "byteOffset").unwrap_or(0);
        if count > 0 {
            let need = (count - 1)
                .checked_mul(stride)
                .and_then(|x| x.checked_add(aoff))
                .and_then(|x| x.checked_add(elem))
                .ok_or_else(|| e("size overflow"))?;
            if need > vdata.len() {
                return Err(e(&format!(
                    "{count} elements need {need} bytes, buffer view has {}",
                    vdata.len()
                )));
            }
        }
        let mut out = Vec::with_capacity(count * comps);
        for i in 0..count {
            let base = aoff + i * stride;
            for c in 0..comps {
                let at = base + c * csize;
                let b = &vdata[at..at + csize];
                out.push(match ct {
                    5120 => b[0] as i8 as f64,
                    5121 => b[0] as f64,
                    5122 => i16::from_le_bytes([b[0], b[1]]) as f64,
                    5123 => u16::from_le_bytes([b[0], b[1]]) as f64,
                    5125 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    _ => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                });
            }
        }
        Ok(out)
    }

    fn node_matrix(&self, node: &Value) -> Result<Mat4> {
        let nums = |key: &str, n: usize| -> Option<Result<Vec<f32>>> {
            let arr = node.get(key)?.as_array();
            Some(match arr {
                Some(a) if a.len() == n && a.iter().all(|x| x.is_number()) => {
                    Ok(a.iter().map(|x| x.as_f64().unwrap_or(0.0) as f32).collect())
                }
                _ => Err(self.err(format!("node {key} must be {n} numbers"))),
            })
        };
        if let Some(m) = nums("matrix", 16) {
            return Ok(Mat4::from_cols_slice(&m?));
        }
        let t = nums("translation", 3)
            .transpose()?
            .map_or(Vec3::ZERO, |v| Vec3::from_slice(&v));
        let r = nums("rotation", 4)
            .transpose()?
            .map_or(Quat::IDENTITY, |v| {
                Quat::from_xyzw(v[0], v[1], v[2], v[3]).normalize()
            });
        let s = nums("scale", 3)
            .transpose()?
            .map_or(Vec3::ONE, |v| Vec3::from_slice(&v));
        Ok(Mat4::from_scale_rotation_translation(s, r, t))
    }

    fn primitives_of(&self, mi: usize, xf: Mat4, out: &mut Vec<GlbPrimitive>) -> Result<()> {
        let mesh = self.item("meshes", mi)?;
        let name = mesh.get("name").and_then(Value::as_str).map(str::to_string);
        let prims = mesh
            .get("primitives")
            .and_then(Value::as_array)
            .cloned()
            .unwrap_or_default();
        for (pi, prim) in prims.iter().enumerate() {
            let mode = prim.get("mode").and_then(Value::as_u64).unwrap_or(4);
            if !(4..=6).contains(&mode) {
                continue;
            }
            let e = |m: String| self.err(format!("meshes[{mi}].primitives[{pi}]: {m}"));
            let pa = prim
                .get("attributes")
                .and_then(|a| idx(a, "POSITION"))
                .ok_or_else(|| e("no POSITION attribute".into()))?;
            let pos = self.accessor(pa, "VEC3", &[5126])?;
            let vertices: Vec<Vec3> = pos
                .chunks_exact(3)
                .map(|c| xf.transform_point3(Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32)))
                .collect();
            if let Some(i) = vertices.iter().position(|v| !v.is_finite()) {
                return Err(e(format!("position {i} is not finite")));
            }
            let n = vertices.len();
            let ids: Vec<u32> = match idx(prim, "indices") {
                Some(ia) => {
                    let raw = self.accessor(ia, "SCALAR", &[5121, 5123, 5125])?;
                    if let Some(bad) = raw.iter().find(|&&i| i >= n as f64) {
                        return Err(e(format!("index {bad} out of range ({n} positions)")));
                    }
                    raw.into_iter().map(|i| i as u32).collect()
                }
                None => (0..n as u32).collect(),
            };
            let faces: Vec<[u32; 3]> = match mode {
                4 => ids.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
                5 => (0..ids.len().saturating_sub(2))
                    .map(|i| {
                        if i % 2 == 0 {
                            [ids[i], ids[i + 1], ids[i + 2]]
                        } else {
                            [ids[i], ids[i + 2], ids[i + 1]]
                        }
                    })
                    .collect(),
                _ => (1..ids.len().saturating_sub(1))
                    .map(|i| [ids[i], ids[i + 1], ids[0]])
                    .collect(),
            };
            let base_color = idx(prim, "material").and_then(|m| {
                let c = self
                    .json
                    .get("materials")?
                    .get(m)?
                    .get("pbrMetallicRoughness")?;
                let f = c.get("baseColorFactor").and_then(Value::as_array);
                match f {
                    Some(a) if a.len() == 4 => {
                        let v: Vec<f32> =
                            a.iter().map(|x| x.as_f64().unwrap_or(1.0) as f32).collect();
                        Some([v[0], v[1], v[2], v[3]])
                    }
                    _ => Some([1.0; 4]),
                }
            });
            out.push(GlbPrimitive {
                mesh_index: mi,
                primitive_index: pi,
                name: name.clone(),
                mesh: TriMesh { vertices, faces },
                base_color,
            });
        }
        Ok(())
    }

    fn visit(
        &self,
        ni: usize,
        parent: Mat4,
        depth: usize,
        budget: &mut usize,
        out: &mut Vec<GlbPrimitive>,
    ) -> Result<()> {
        if depth > 64 {
            return Err(self.err("node hierarchy deeper than 64 (a cycle?)".into()));
        }
        // Shared children make the hierarchy a DAG: bound the total work on hostile files.
        *budget = budget
            .checked_sub(1)
            .ok_or_else(|| self.err("too many node instances".into()))?;
        let node = self.item("nodes", ni)?;
        let xf = parent * self.node_matrix(node)?;
        if let Some(mi) = idx(node, "mesh") {
            self.primitives_of(mi, xf, out)?;
        }
        if let Some(children) = node.get("children").and_then(Value::as_array) {
            for c in children {
                let c = c
                    .as_u64()
                    .ok_or_else(|| self.err(format!("nodes[{ni}]: bad child")))?;
                self.visit(c as usize, xf, depth + 1, budget, out)?;
            }
        }
        Ok(())
    }
}

/// Parses GLB bytes into triangle primitives in world coordinates; `path` is only used in
/// error messages. Without a scene, every mesh is returned untransformed in mesh order.
pub fn parse_glb(bytes: &[u8], path: &Path) -> Result<Vec<GlbPrimitive>> {
    let (json, bin) = container(bytes, path)?;
    let doc = Doc { json, bin, path };
    let mut out = Vec::new();
    let scene_i = idx(&doc.json, "scene").unwrap_or(0);
    match doc.json.get("scenes").and_then(|s| s.get(scene_i)) {
        Some(scene) => {
            let roots = scene
                .get("nodes")
                .and_then(Value::as_array)
                .cloned()
                .unwrap_or_default();
            let mut budget = 1 << 16;
            for r in roots {
                let r = r
                    .as_u64()
                    .ok_or_else(|| doc.err("scene lists a bad node".into()))?;
                doc.visit(r as usize, Mat4::IDENTITY, 0, &mut budget, &mut out)?;
            }
        }
        None => {
            let n = doc
                .json
                .get("meshes")
                .and_then(Value::as_array)
                .map_or(0, Vec::len);
            for mi in 0..n {
                doc.primitives_of(mi, Mat4::IDENTITY, &mut out)?;
            }
        }
    }
    Ok(out)
}

/// Reads the triangle primitives of a GLB file (see [`parse_glb`]).
pub fn read_glb(path: impl AsRef<Path>) -> Result<Vec<GlbPrimitive>> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| GeomError::io(path, e))?;
    parse_glb(&bytes, path)
}

/// Reads a GLB file and merges all its triangle primitives into one mesh.
pub fn read_glb_merged(path: impl AsRef<Path>) -> Result<TriMesh> {
    let path = path.as_ref();
    let mut out = TriMesh::default();
    for p in read_glb(path)? {
        out.append(&p.mesh)
            .map_err(|e| GeomError::format(path, e.to_string()))?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::glb::{assemble, encode_glb, two_mesh_fixture, GlbMesh, DEFAULT_COLOR};
    use super::*;
    use serde_json::json;

    fn p() -> &'static Path {
        Path::new("t.glb")
    }

    #[test]
    fn round_trip_two_meshes() {
        let (s, g, bytes) = two_mesh_fixture();
        let prims = parse_glb(&bytes, p()).unwrap();
        assert_eq!(prims.len(), 2);
        assert_eq!(prims[0].mesh, s);
        assert_eq!(prims[1].mesh, g);
        assert_eq!(prims[1].name.as_deref(), Some("sheet"));
        assert_eq!(prims[0].base_color, Some([1.0, 0.0, 0.0, 1.0]));
    }

    #[test]
    fn strips_u16_indices_and_node_transform() {
        let mut bin = Vec::new();
        for v in [0f32, 0., 0., 1., 0., 0., 0., 1., 0., 1., 1., 0.] {
            bin.extend_from_slice(&v.to_le_bytes());
        }
        for i in [0u16, 1, 2, 3] {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        let doc = json!({
            "asset": {"version": "2.0"}, "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [{"children": [1], "translation": [0.0, 0.0, 2.0]}, {"mesh": 0, "scale": [2.0, 2.0, 2.0]}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 5}]}],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
                {"bufferView": 0, "byteOffset": 48, "componentType": 5123, "count": 4, "type": "SCALAR"}],
            "bufferViews": [{"buffer": 0, "byteLength": 56}],
            "buffers": [{"byteLength": 56}]
        });
        let prims = parse_glb(&assemble(&doc, &bin), p()).unwrap();
        assert_eq!(prims[0].mesh.faces, vec![[0, 1, 2], [1, 3, 2]]);
        assert_eq!(prims[0].mesh.vertices[3], Vec3::new(2.0, 2.0, 2.0));
    }

    #[test]
    fn errors() {
        let s = TriMesh::icosphere(0, 1.0);
        let good = encode_glb(&[GlbMesh {
            mesh: &s,
            name: "s",
            color: DEFAULT_COLOR,
        }])
        .unwrap();
        let mut bad = good.clone();
        bad[0] = b'x';
        let e = parse_glb(&bad, p()).unwrap_err().to_string();
        assert!(e.contains("t.glb: byte 0") && e.contains("magic"), "{e}");
        let e = parse_glb(&good[..good.len() - 10], p())
            .unwrap_err()
            .to_string();
        assert!(e.contains("byte 8"), "{e}");
        let mut cut = good[..good.len() - 10].to_vec();
        let n = cut.len() as u32;
        cut[8..12].copy_from_slice(&n.to_le_bytes());
        let e = parse_glb(&cut, p()).unwrap_err().to_string();
        assert!(e.contains("runs past the end"), "{e}");
        assert!(parse_glb(b"glTF", p()).is_err());
        // Index out of range.
        let doc = json!({"meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 1, "type": "VEC3"},
                          {"bufferView": 0, "componentType": 5121, "count": 3, "type": "SCALAR"}],
            "bufferViews": [{"buffer": 0, "byteLength": 12}], "buffers": [{"byteLength": 12}]});
        let e = parse_glb(&assemble(&doc, &[0x40; 12]), p())
            .unwrap_err()
            .to_string();
        assert!(e.contains("out of range"), "{e}");
        // Accessor past its view.
        let doc = json!({"meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 2, "type": "VEC3"}],
            "bufferViews": [{"buffer": 0, "byteLength": 12}], "buffers": [{"byteLength": 12}]});
        let e = parse_glb(&assemble(&doc, &[0; 12]), p())
            .unwrap_err()
            .to_string();
        assert!(e.contains("accessors[0]"), "{e}");
    }
}
