//! The body faces file: every body of a dataset shares the body model's triangles, stored
//! once as `body_faces.safetensors` with one tensor `faces` u32 `[F,3]`.

use std::path::Path;

use geom::io::le::{from_le, to_le};
use safetensors::{tensor::TensorView, Dtype, SafeTensors};

use crate::error::{DatasetError, Result};

/// Writes `faces` (`[F]` vertex index triples) to `path` atomically.
pub fn write(path: &Path, faces: &[[u32; 3]]) -> Result<()> {
    let bytes = to_le(faces.iter().flatten().copied());
    let view = TensorView::new(Dtype::U32, vec![faces.len(), 3], &bytes)
        .map_err(|e| DatasetError::Invalid(format!("body faces: {e}")))?;
    let out = safetensors::serialize([("faces", view)], None)
        .map_err(|e| DatasetError::Invalid(format!("body faces: {e}")))?;
    geom::io::write_bytes_atomic(path, &out)?;
    Ok(())
}

/// Reads the faces (`[F]` triples) of `bytes`, the file at `path`.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Vec<[u32; 3]>> {
    let st = SafeTensors::deserialize(bytes)
        .map_err(|e| DatasetError::corrupt(path, format!("not a body faces file: {e}")))?;
    let t = st
        .tensor("faces")
        .map_err(|_| DatasetError::corrupt(path, "no faces tensor"))?;
    if t.dtype() != Dtype::U32 || t.shape().len() != 2 || t.shape()[1] != 3 {
        return Err(DatasetError::corrupt(path, "faces must be u32 [F,3]"));
    }
    Ok(from_le::<u32>(t.data())
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("f.safetensors");
        let faces = vec![[0, 1, 2], [2, 1, 3]];
        write(&p, &faces).unwrap();
        assert_eq!(parse(&std::fs::read(&p).unwrap(), &p).unwrap(), faces);
        assert!(parse(b"garbage", &p)
            .unwrap_err()
            .to_string()
            .contains("f.safetensors"));
    }
}
