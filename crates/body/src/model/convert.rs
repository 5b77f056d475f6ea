//! Conversion of the unpacked MakeHuman `mpfb2` folder into the compact body file.

use std::collections::{BTreeMap, HashMap};
use std::io::Read;
use std::path::Path;

use safetensors::{tensor::TensorView, Dtype};
use serde_json::Value;

use geom::io::le::to_le;

use super::{BoneDef, BODY_VERTEX_COUNT, FORMAT};
use crate::assets::WHEEL_SHA256;
use crate::BodyError;

/// Target folders (relative to `targets/`) whose files are phenotype macro targets.
const TARGET_DIRS: [&str; 4] = [
    "macrodetails",
    "macrodetails/height",
    "macrodetails/proportions",
    "breast",
];
/// Decimetres (MakeHuman's unit) to metres.
const DM: f32 = 0.1;

/// The parts of `3dobjs/base.obj` the body needs.
struct BaseObj {
    /// All vertices, metres.
    vertices: Vec<[f32; 3]>,
    /// Faces of the `body` group as vertex-index polygons.
    body_faces: Vec<Vec<u32>>,
    /// Vertex indices used by the faces of each group.
    groups: HashMap<String, Vec<u32>>,
}

/// Reads `mpfb2` and writes the compact body file `out` (atomically).
pub fn convert_assets(mpfb2: &Path, out: &Path) -> Result<(), BodyError> {
    let base = read_base_obj(&mpfb2.join("3dobjs/base.obj"))?;
    let (bones, regressors) = read_rig(&mpfb2.join("rigs/standard/rig.cmu_mb.json"), &base)?;
    let weight_rows = read_weights(&mpfb2.join("rigs/standard/weights.cmu_mb.json"), &bones)?;
    let tpose = read_tpose(&mpfb2.join("poses/cmu_mb_fk/t-pose.json"), &bones)?;

    // Keep the body vertices at their own indices, then the extra vertices the joint
    // regressors average, renumbered.
    let mut remap: HashMap<u32, u32> = (0..BODY_VERTEX_COUNT as u32).map(|i| (i, i)).collect();
    let mut kept: Vec<u32> = (0..BODY_VERTEX_COUNT as u32).collect();
    let regressors: Vec<Vec<u32>> = regressors
        .into_iter()
        .map(|r| {
            r.into_iter()
                .map(|i| {
                    *remap.entry(i).or_insert_with(|| {
                        kept.push(i);
                        kept.len() as u32 - 1
                    })
                })
                .collect()
        })
        .collect();
    if kept.len() > u16::MAX as usize {
        return Err(BodyError::asset(
            mpfb2,
            "too many vertices for 16-bit target indices",
        ));
    }

    let mut faces: Vec<u32> = Vec::new();
    for poly in &base.body_faces {
        if poly.iter().any(|&i| i as usize >= BODY_VERTEX_COUNT) {
            return Err(BodyError::asset(
                mpfb2.join("3dobjs/base.obj"),
                "body face uses a non-body vertex",
            ));
        }
        for k in 1..poly.len() - 1 {
            faces.extend([poly[0], poly[k], poly[k + 1]]);
        }
    }

    let mut tensors: BTreeMap<String, (Dtype, Vec<usize>, Vec<u8>)> = BTreeMap::new();
    let vertices: Vec<f32> = kept
        .iter()
        .flat_map(|&i| base.vertices[i as usize])
        .collect();
    tensors.insert(
        "vertices".into(),
        (
            Dtype::F32,
            vec![kept.len(), 3],
            to_le(vertices.iter().copied()),
        ),
    );
    tensors.insert(
        "faces".into(),
        (
            Dtype::U32,
            vec![faces.len() / 3, 3],
            to_le(faces.iter().copied()),
        ),
    );
    let (mut offsets, mut wb, mut wv) = (vec![0u32], Vec::<u16>::new(), Vec::<f32>::new());
    for row in &weight_rows {
        let total: f32 = row.iter().map(|(_, w)| w).sum();
        for &(b, w) in row {
            wb.push(b);
            wv.push(w / total);
        }
        offsets.push(wb.len() as u32);
    }
    tensors.insert(
        "weights.offsets".into(),
        (
            Dtype::U32,
            vec![offsets.len()],
            to_le(offsets.iter().copied()),
        ),
    );
    tensors.insert(
        "weights.bones".into(),
        (Dtype::U16, vec![wb.len()], to_le(wb.iter().copied())),
    );
    tensors.insert(
        "weights.values".into(),
        (Dtype::F32, vec![wv.len()], to_le(wv.iter().copied())),
    );
    let mut reg_off = vec![0u32];
    let mut reg_idx: Vec<u32> = Vec::new();
    for r in &regressors {
        reg_idx.extend(r);
        reg_off.push(reg_idx.len() as u32);
    }
    tensors.insert(
        "regressors.offsets".into(),
        (
            Dtype::U32,
            vec![reg_off.len()],
            to_le(reg_off.iter().copied()),
        ),
    );
    tensors.insert(
        "regressors.indices".into(),
        (
            Dtype::U32,
            vec![reg_idx.len()],
            to_le(reg_idx.iter().copied()),
        ),
    );

    for dir in TARGET_DIRS {
        let dir_path = mpfb2.join("targets").join(dir);
        let mut names: Vec<_> = std::fs::read_dir(&dir_path)
            .map_err(|e| BodyError::asset(&dir_path, e.to_string()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.to_string_lossy().ends_with(".target.gz"))
            .collect();
        names.sort();
        for path in names {
            let name = path
                .file_name()
                .unwrap()
                .to_string_lossy()
                .trim_end_matches(".target.gz")
                .to_string();
            let (index, delta) = read_target(&path, &remap)?;
            tensors.insert(
                format!("target/{name}/index"),
                (Dtype::U16, vec![index.len()], to_le(index.iter().copied())),
            );
            tensors.insert(
                format!("target/{name}/delta"),
                (
                    Dtype::I16,
                    vec![index.len(), 3],
                    to_le(delta.iter().copied()),
                ),
            );
        }
    }

    let views: Vec<(String, TensorView<'_>)> = tensors
        .iter()
        .map(|(k, (d, s, b))| {
            (
                k.clone(),
                TensorView::new(*d, s.clone(), b).expect("consistent tensor"),
            )
        })
        .collect();
    let meta: HashMap<String, String> = HashMap::from([
        ("format".to_string(), FORMAT.to_string()),
        ("source_sha256".to_string(), WHEEL_SHA256.to_string()),
        (
            "bones".to_string(),
            serde_json::to_string(&bones).expect("bones serialise"),
        ),
        (
            "tpose".to_string(),
            serde_json::to_string(&tpose).expect("tpose serialises"),
        ),
    ]);
    let bytes = safetensors::serialize(views, Some(meta))
        .map_err(|e| BodyError::asset(out, e.to_string()))?;
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir).map_err(|e| BodyError::asset(dir, e.to_string()))?;
    }
    geom::io::write_atomic(out, |w| w.write_all(&bytes))
        .map_err(|e| BodyError::asset(out, e.to_string()))
}

fn read_base_obj(path: &Path) -> Result<BaseObj, BodyError> {
    let text = std::fs::read_to_string(path).map_err(|e| BodyError::asset(path, e.to_string()))?;
    let mut vertices = Vec::new();
    let mut body_faces = Vec::new();
    let mut groups: HashMap<String, Vec<u32>> = HashMap::new();
    let mut group = String::new();
    for (n, line) in text.lines().enumerate() {
        let bad = |m: &str| BodyError::asset(path, format!("line {}: {m}", n + 1));
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f32> = it
                    .map(str::parse)
                    .collect::<Result<_, _>>()
                    .map_err(|_| bad("bad vertex"))?;
                if c.len() != 3 || c.iter().any(|x| !x.is_finite()) {
                    return Err(bad("vertex needs three finite coordinates"));
                }
                vertices.push([c[0] * DM, c[1] * DM, c[2] * DM]);
            }
            Some("g") => group = it.next().unwrap_or("").to_string(),
            Some("f") => {
                let poly: Vec<u32> = it
                    .map(|t| {
                        t.split('/')
                            .next()
                            .unwrap_or("")
                            .parse::<u32>()
                            .ok()
                            .filter(|&i| i >= 1)
                            .map(|i| i - 1)
                    })
                    .collect::<Option<_>>()
                    .ok_or_else(|| bad("bad face index"))?;
                if poly.len() < 3 || poly.iter().any(|&i| i as usize >= vertices.len()) {
                    return Err(bad("face index out of range"));
                }
                let g = groups.entry(group.clone()).or_default();
                for &i in &poly {
                    if !g.contains(&i) {
                        g.push(i);
                    }
                }
                if group == "body" {
                    body_faces.push(poly);
                }
            }
            _ => {}
        }
    }
    let body = groups
        .get("body")
        .ok_or_else(|| BodyError::asset(path, "no body group"))?;
    if body.len() != BODY_VERTEX_COUNT || body.iter().any(|&i| i as usize >= BODY_VERTEX_COUNT) {
        return Err(BodyError::asset(
            path,
            format!("body group must use vertices 0..{BODY_VERTEX_COUNT}"),
        ));
    }
    Ok(BaseObj {
        vertices,
        body_faces,
        groups,
    })
}

/// Bone definitions in parent-before-child order and the vertex lists averaged for each
/// bone's head and tail (`[2B]`, original base-mesh indices).
fn read_rig(path: &Path, base: &BaseObj) -> Result<(Vec<BoneDef>, Vec<Vec<u32>>), BodyError> {
    let bad = |m: String| BodyError::asset(path, m);
    let json = read_json(path)?;
    let rig = json
        .as_object()
        .ok_or_else(|| bad("not a JSON object".into()))?;
    let parent_of = |name: &str| {
        rig[name]
            .get("parent")
            .and_then(Value::as_str)
            .unwrap_or("")
            .to_string()
    };
    // Depth-first from the root so that parents precede children; children by name.
    let mut names: Vec<&String> = rig.keys().collect();
    names.sort();
    let mut order: Vec<String> = Vec::new();
    let mut stack: Vec<String> = names
        .iter()
        .filter(|n| parent_of(n).is_empty())
        .map(|n| n.to_string())
        .collect();
    if stack.len() != 1 {
        return Err(bad(format!(
            "expected one root bone, found {}",
            stack.len()
        )));
    }
    while let Some(n) = stack.pop() {
        let mut kids: Vec<String> = names
            .iter()
            .filter(|k| parent_of(k) == n)
            .map(|k| k.to_string())
            .collect();
        kids.reverse();
        order.push(n);
        stack.extend(kids);
    }
    if order.len() != rig.len() {
        return Err(bad("bones unreachable from the root".into()));
    }
    let mut bones = Vec::new();
    let mut regressors = Vec::new();
    for name in &order {
        let def = &rig[name];
        let parent = Some(parent_of(name))
            .filter(|p| !p.is_empty())
            .map(|p| order.iter().position(|o| *o == p).unwrap());
        let roll = def
            .get("roll")
            .and_then(Value::as_f64)
            .ok_or_else(|| bad(format!("{name}: no roll")))? as f32;
        for end in ["head", "tail"] {
            let e = def
                .get(end)
                .ok_or_else(|| bad(format!("{name}: no {end}")))?;
            regressors.push(regressor(e, base).map_err(|m| bad(format!("{name} {end}: {m}")))?);
        }
        bones.push(BoneDef {
            name: name.clone(),
            parent,
            roll,
        });
    }
    Ok((bones, regressors))
}

/// The vertices whose mean places a joint: a joint cube's vertices, one vertex, or a list.
fn regressor(e: &Value, base: &BaseObj) -> Result<Vec<u32>, String> {
    let idx = |v: &Value| {
        v.as_u64()
            .map(|i| i as u32)
            .filter(|&i| (i as usize) < base.vertices.len())
    };
    let out = match e.get("strategy").and_then(Value::as_str) {
        Some("CUBE") => {
            let cube = e
                .get("cube_name")
                .and_then(Value::as_str)
                .ok_or("CUBE without cube_name")?;
            base.groups
                .get(cube)
                .cloned()
                .ok_or(format!("no group {cube} in base.obj"))?
        }
        Some("VERTEX") => vec![e
            .get("vertex_index")
            .and_then(idx)
            .ok_or("bad vertex_index")?],
        Some("MEAN") => e
            .get("vertex_indices")
            .and_then(Value::as_array)
            .ok_or("MEAN without vertex_indices")?
            .iter()
            .map(idx)
            .collect::<Option<Vec<_>>>()
            .ok_or("bad vertex index")?,
        other => return Err(format!("unknown strategy {other:?}")),
    };
    if out.is_empty() {
        return Err("no vertices".into());
    }
    Ok(out)
}

/// Per body vertex `(bone, weight)` rows from `{"weights": {bone: [[vertex, w], ...]}}`.
fn read_weights(path: &Path, bones: &[BoneDef]) -> Result<Vec<Vec<(u16, f32)>>, BodyError> {
    let bad = |m: String| BodyError::asset(path, m);
    let json = read_json(path)?;
    let table = json
        .get("weights")
        .and_then(Value::as_object)
        .ok_or_else(|| bad("no weights object".into()))?;
    let mut rows = vec![Vec::new(); BODY_VERTEX_COUNT];
    for (bone, list) in table {
        let b = bones
            .iter()
            .position(|d| d.name == *bone)
            .ok_or_else(|| bad(format!("unknown bone {bone}")))?;
        for pair in list
            .as_array()
            .ok_or_else(|| bad(format!("{bone}: not a list")))?
        {
            let (v, w) = (
                pair.get(0).and_then(Value::as_u64),
                pair.get(1).and_then(Value::as_f64),
            );
            let (Some(v), Some(w)) = (v, w) else {
                return Err(bad(format!("{bone}: bad [vertex, weight] pair")));
            };
            if (v as usize) < BODY_VERTEX_COUNT && w > 0.0 {
                rows[v as usize].push((b as u16, w as f32));
            }
        }
    }
    if let Some(v) = rows.iter().position(Vec::is_empty) {
        return Err(bad(format!("body vertex {v} has no weight")));
    }
    Ok(rows)
}

fn read_tpose(path: &Path, bones: &[BoneDef]) -> Result<BTreeMap<String, [f32; 3]>, BodyError> {
    let json = read_json(path)?;
    let rot = json
        .get("bone_rotations")
        .and_then(Value::as_object)
        .ok_or_else(|| BodyError::asset(path, "no bone_rotations"))?;
    rot.iter()
        .map(|(name, e)| {
            let v: Option<Vec<f32>> = e.as_array().map(|a| {
                a.iter()
                    .filter_map(|x| x.as_f64().map(|x| x as f32))
                    .collect()
            });
            match v {
                Some(v) if v.len() == 3 && bones.iter().any(|b| b.name == *name) => {
                    Ok((name.clone(), [v[0], v[1], v[2]]))
                }
                _ => Err(BodyError::asset(
                    path,
                    format!("bad rotation for bone {name}"),
                )),
            }
        })
        .collect()
}

fn read_json(path: &Path) -> Result<Value, BodyError> {
    let text = std::fs::read_to_string(path).map_err(|e| BodyError::asset(path, e.to_string()))?;
    serde_json::from_str(&text).map_err(|e| BodyError::asset(path, format!("invalid JSON: {e}")))
}

/// A target file's entries for kept vertices: new indices and offsets in 0.1 mm.
fn read_target(path: &Path, remap: &HashMap<u32, u32>) -> Result<(Vec<u16>, Vec<i16>), BodyError> {
    let mut text = String::new();
    flate2::read::GzDecoder::new(
        std::fs::File::open(path).map_err(|e| BodyError::asset(path, e.to_string()))?,
    )
    .read_to_string(&mut text)
    .map_err(|e| BodyError::asset(path, format!("not a gzip text file: {e}")))?;
    let mut index = Vec::new();
    let mut delta = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        let Some(first) = it.next() else { continue };
        if first.starts_with('#') {
            continue;
        }
        let bad = || BodyError::asset(path, format!("line {}: expected `index dx dy dz`", n + 1));
        let i: u32 = first.parse().map_err(|_| bad())?;
        let d: Vec<f32> = it
            .map(str::parse)
            .collect::<Result<_, _>>()
            .map_err(|_| bad())?;
        if d.len() != 3 {
            return Err(bad());
        }
        let Some(&k) = remap.get(&i) else { continue };
        index.push(k as u16);
        for x in d {
            // Decimetres with three decimals -> tenths of a millimetre, exactly.
            let q = (x * 1000.0).round();
            if !(i16::MIN as f32..=i16::MAX as f32).contains(&q) {
                return Err(BodyError::asset(
                    path,
                    format!("line {}: offset {x} dm too large", n + 1),
                ));
            }
            delta.push(q as i16);
        }
    }
    Ok((index, delta))
}
