//! glTF 2.0 binary (GLB) writing.
//!
//! One node and one mesh per input mesh, each with a single triangle primitive: `POSITION`
//! (float VEC3 with the min/max the spec requires), `NORMAL` (unit, area-weighted), `u32`
//! indices, and a double-sided PBR material with the mesh's base colour. Every buffer view
//! starts on a 4-byte boundary; the JSON chunk is padded with spaces, the BIN chunk with zeros.

use std::path::Path;

use glam::Vec3;
use serde_json::{json, Value};

use super::atomic::write_atomic;
use crate::error::{GeomError, Result};
use crate::mesh::TriMesh;

/// `glTF` in little endian: the first four bytes of a GLB file.
pub const GLB_MAGIC: u32 = 0x4654_6C67;
/// Chunk type of the JSON chunk (`JSON`).
pub const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Chunk type of the binary chunk (`BIN\0`).
pub const CHUNK_BIN: u32 = 0x004E_4942;

/// Default base colour of [`super::write_mesh`] GLB output: a light grey (linear RGBA).
pub const DEFAULT_COLOR: [f32; 4] = [0.8, 0.8, 0.8, 1.0];

/// One mesh to put in a GLB file.
#[derive(Clone, Copy, Debug)]
pub struct GlbMesh<'a> {
    /// The geometry; must validate and have at least one face.
    pub mesh: &'a TriMesh,
    /// Node, mesh and material name.
    pub name: &'a str,
    /// Base colour, linear RGBA in [0, 1].
    pub color: [f32; 4],
}

pub(crate) const ARRAY_BUFFER: u32 = 34962;
pub(crate) const ELEMENT_ARRAY_BUFFER: u32 = 34963;
pub(crate) const FLOAT: u32 = 5126;
pub(crate) const UNSIGNED_INT: u32 = 5125;
const TRIANGLES: u32 = 4;

/// The f32 components as f64 so the JSON holds their exact values: validators compare
/// accessor min/max with the data read as doubles.
pub(crate) fn exact(v: Vec3) -> [f64; 3] {
    v.as_dvec3().to_array()
}

fn push_vec3s(bin: &mut Vec<u8>, vs: impl Iterator<Item = Vec3>) {
    for v in vs {
        for c in v.to_array() {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
}

/// Encodes meshes as a GLB byte vector. Fails when the list is empty, a mesh has no face, does
/// not validate, or a colour component is outside [0, 1].
pub fn encode_glb(meshes: &[GlbMesh]) -> Result<Vec<u8>> {
    encode(meshes, &[])
}

/// Encodes meshes as [`encode_glb`] does, each with optional per-vertex colours: where
/// `colors[i]` is `Some`, mesh `i` gets a `COLOR_0` attribute (float RGB, linear, one per
/// vertex, each in [0, 1]; glTF multiplies them with the base colour, so heat maps take a
/// white one). `colors` may be shorter than `meshes` (the rest get none). Fails as
/// [`encode_glb`] does, and when a colour list's length is not the mesh's vertex count or a
/// component is outside [0, 1].
pub fn encode_glb_colored(meshes: &[GlbMesh], colors: &[Option<&[[f32; 3]]>]) -> Result<Vec<u8>> {
    if colors.len() > meshes.len() {
        return Err(GeomError::InvalidInput(format!(
            "GLB: {} colour lists for {} meshes",
            colors.len(),
            meshes.len()
        )));
    }
    for (i, (m, c)) in meshes.iter().zip(colors).enumerate() {
        let Some(c) = c else { continue };
        if c.len() != m.mesh.vertices.len() {
            return Err(GeomError::InvalidInput(format!(
                "GLB mesh {i} ({}): {} vertex colours for {} vertices",
                m.name,
                c.len(),
                m.mesh.vertices.len()
            )));
        }
        if c.as_flattened().iter().any(|v| !(0.0..=1.0).contains(v)) {
            return Err(GeomError::InvalidInput(format!(
                "GLB mesh {i} ({}): a vertex colour outside [0, 1]",
                m.name
            )));
        }
    }
    encode(meshes, colors)
}

/// [`encode_glb`] with the optional vertex colours of [`encode_glb_colored`] (checked there).
fn encode(meshes: &[GlbMesh], colors: &[Option<&[[f32; 3]]>]) -> Result<Vec<u8>> {
    if meshes.is_empty() {
        return Err(GeomError::InvalidInput(
            "GLB needs at least one mesh".into(),
        ));
    }
    let mut bin: Vec<u8> = Vec::new();
    let (mut views, mut accessors, mut gmeshes, mut materials, mut nodes) =
        (vec![], vec![], vec![], vec![], vec![]);
    for (i, m) in meshes.iter().enumerate() {
        let mesh = m.mesh;
        mesh.validate()
            .map_err(|e| GeomError::InvalidInput(format!("GLB mesh {i} ({}): {e}", m.name)))?;
        if mesh.faces.is_empty() {
            return Err(GeomError::InvalidInput(format!(
                "GLB mesh {i} ({}) has no faces",
                m.name
            )));
        }
        if m.color.iter().any(|c| !(0.0..=1.0).contains(c)) {
            return Err(GeomError::InvalidInput(format!(
                "GLB mesh {i} ({}): colour {:?} outside [0, 1]",
                m.name, m.color
            )));
        }
        let n = mesh.vertices.len();
        let (lo, hi) = mesh.bounds().unwrap_or((Vec3::ZERO, Vec3::ZERO));
        let normals = mesh.vertex_normals();
        let base = views.len();
        // Positions.
        let off = bin.len();
        push_vec3s(&mut bin, mesh.vertices.iter().copied());
        views.push(
            json!({"buffer": 0, "byteOffset": off, "byteLength": 12 * n, "target": ARRAY_BUFFER}),
        );
        // Normals (zero normals of isolated or degenerate vertices become +Y: glTF wants unit).
        let off = bin.len();
        push_vec3s(
            &mut bin,
            normals
                .iter()
                .map(|&v| if v == Vec3::ZERO { Vec3::Y } else { v }),
        );
        views.push(
            json!({"buffer": 0, "byteOffset": off, "byteLength": 12 * n, "target": ARRAY_BUFFER}),
        );
        // Indices.
        let off = bin.len();
        for &i in mesh.faces.as_flattened() {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        views.push(
            json!({"buffer": 0, "byteOffset": off, "byteLength": 12 * mesh.faces.len(),
                          "target": ELEMENT_ARRAY_BUFFER}),
        );
        accessors.push(
            json!({"bufferView": base, "componentType": FLOAT, "count": n, "type": "VEC3",
                              "min": exact(lo), "max": exact(hi)}),
        );
        accessors.push(
            json!({"bufferView": base + 1, "componentType": FLOAT, "count": n, "type": "VEC3"}),
        );
        accessors.push(
            json!({"bufferView": base + 2, "componentType": UNSIGNED_INT,
                              "count": 3 * mesh.faces.len(), "type": "SCALAR"}),
        );
        let mut attributes = json!({"POSITION": base, "NORMAL": base + 1});
        if let Some(Some(c)) = colors.get(i) {
            let off = bin.len();
            for &v in c.as_flattened() {
                bin.extend_from_slice(&v.to_le_bytes());
            }
            views.push(json!({"buffer": 0, "byteOffset": off, "byteLength": 12 * n,
                              "target": ARRAY_BUFFER}));
            attributes["COLOR_0"] = json!(accessors.len());
            accessors.push(
                json!({"bufferView": views.len() - 1, "componentType": FLOAT,
                                  "count": n, "type": "VEC3"}),
            );
        }
        gmeshes.push(json!({"name": m.name, "primitives": [{
            "attributes": attributes,
            "indices": base + 2, "material": i, "mode": TRIANGLES}]}));
        materials.push(
            json!({"name": m.name, "doubleSided": true, "pbrMetallicRoughness": {
            "baseColorFactor": m.color, "metallicFactor": 0.0, "roughnessFactor": 0.8}}),
        );
        nodes.push(json!({"name": m.name, "mesh": i}));
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": "garnet geom"},
        "scene": 0,
        "scenes": [{"nodes": (0..meshes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": gmeshes,
        "materials": materials,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}],
    });
    Ok(assemble(&doc, &bin))
}

/// Builds the GLB container: 12-byte header, space-padded JSON chunk, zero-padded BIN chunk.
pub(crate) fn assemble(doc: &Value, bin: &[u8]) -> Vec<u8> {
    let mut json = serde_json::to_vec(doc).unwrap_or_default();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let bin_len = bin.len().div_ceil(4) * 4;
    let total = 12 + 8 + json.len() + if bin.is_empty() { 0 } else { 8 + bin_len };
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(&GLB_MAGIC.to_le_bytes());
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(&CHUNK_JSON.to_le_bytes());
    out.extend_from_slice(&json);
    if !bin.is_empty() {
        out.extend_from_slice(&(bin_len as u32).to_le_bytes());
        out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
        out.extend_from_slice(bin);
        out.resize(total, 0);
    }
    out
}

/// Writes meshes as a GLB file, atomically (see [`encode_glb`] for the failure cases).
pub fn write_glb(path: impl AsRef<Path>, meshes: &[GlbMesh]) -> Result<()> {
    let bytes = encode_glb(meshes)?;
    write_atomic(path, |w| w.write_all(&bytes))
}

/// Test fixture: a red icosphere and a default-coloured grid sheet, and their GLB bytes.
#[cfg(test)]
pub(crate) fn two_mesh_fixture() -> (TriMesh, TriMesh, Vec<u8>) {
    let s = TriMesh::icosphere(1, 0.5);
    let g = TriMesh::grid(3, 2, 0.1);
    let bytes = encode_glb(&fixture_meshes(&s, &g)).unwrap();
    (s, g, bytes)
}

/// The fixture's two meshes: `s` red, `g` in the default colour.
#[cfg(test)]
fn fixture_meshes<'a>(s: &'a TriMesh, g: &'a TriMesh) -> [GlbMesh<'a>; 2] {
    [
        GlbMesh {
            mesh: s,
            name: "sphere",
            color: [1.0, 0.0, 0.0, 1.0],
        },
        GlbMesh {
            mesh: g,
            name: "sheet",
            color: DEFAULT_COLOR,
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_is_aligned_and_json_is_valid() {
        let (s, _, bytes) = two_mesh_fixture();
        assert_eq!(bytes.len() % 4, 0);
        assert_eq!(&bytes[0..4], b"glTF");
        let total = u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize;
        assert_eq!(total, bytes.len());
        let jlen = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        assert_eq!(jlen % 4, 0);
        let doc: Value = serde_json::from_slice(&bytes[20..20 + jlen]).unwrap();
        assert_eq!(
            doc["accessors"][0]["max"][1].as_f64().unwrap() as f32,
            s.bounds().unwrap().1.y
        );
        assert_eq!(doc["materials"][1]["doubleSided"], true);
        for v in doc["bufferViews"].as_array().unwrap() {
            assert_eq!(v["byteOffset"].as_u64().unwrap() % 4, 0);
        }
        let bin_hdr = 20 + jlen;
        assert_eq!(&bytes[bin_hdr + 4..bin_hdr + 8], b"BIN\0");
    }

    #[test]
    fn vertex_colours_add_color_0_and_leave_the_rest_alike() {
        let (s, g, plain) = two_mesh_fixture();
        let meshes = fixture_meshes(&s, &g);
        assert_eq!(encode_glb_colored(&meshes, &[]).unwrap(), plain);
        let colors = vec![[0.25, 0.5, 1.0]; g.vertices.len()];
        let bytes = encode_glb_colored(&meshes, &[None, Some(&colors)]).unwrap();
        let prims = super::super::parse_glb(&bytes, Path::new("c.glb")).unwrap();
        assert_eq!(prims.len(), 2);
        let jlen = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        let doc: Value = serde_json::from_slice(&bytes[20..20 + jlen]).unwrap();
        let attrs = &doc["meshes"][1]["primitives"][0]["attributes"];
        let acc = &doc["accessors"][attrs["COLOR_0"].as_u64().unwrap() as usize];
        assert_eq!(acc["count"].as_u64().unwrap() as usize, g.vertices.len());
        assert!(doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"].is_null());
        let short = vec![[0.0; 3]; 2];
        assert!(encode_glb_colored(&meshes, &[Some(&short)]).is_err());
        let bad = vec![[2.0, 0.0, 0.0]; s.vertices.len()];
        assert!(encode_glb_colored(&meshes, &[Some(&bad)]).is_err());
    }

    #[test]
    fn rejects_bad_input() {
        assert!(encode_glb(&[]).is_err());
        let empty = TriMesh::default();
        assert!(encode_glb(&[GlbMesh {
            mesh: &empty,
            name: "e",
            color: DEFAULT_COLOR
        }])
        .is_err());
        let mut nan = TriMesh::icosphere(0, 1.0);
        nan.vertices[0].x = f32::NAN;
        assert!(encode_glb(&[GlbMesh {
            mesh: &nan,
            name: "n",
            color: DEFAULT_COLOR
        }])
        .is_err());
        let s = TriMesh::icosphere(0, 1.0);
        assert!(encode_glb(&[GlbMesh {
            mesh: &s,
            name: "c",
            color: [2.0, 0.0, 0.0, 1.0]
        }])
        .is_err());
    }
}
