//! Little-endian packing of plain number arrays, for binary containers (safetensors), and
//! the checked lookup of a safetensors file's tensors.

use safetensors::{tensor::TensorView, Dtype, SafeTensors};

/// Numbers that pack to and from little-endian bytes.
pub trait LeBytes: Copy {
    /// Bytes per value.
    const SIZE: usize;
    /// Appends the value's little-endian bytes to `out`.
    fn put(self, out: &mut Vec<u8>);
    /// The value of `SIZE` little-endian bytes.
    fn get(bytes: &[u8]) -> Self;
}

macro_rules! le_bytes {
    ($($t:ty),*) => {$(
        impl LeBytes for $t {
            const SIZE: usize = std::mem::size_of::<$t>();
            fn put(self, out: &mut Vec<u8>) {
                out.extend_from_slice(&self.to_le_bytes());
            }
            fn get(bytes: &[u8]) -> Self {
                <$t>::from_le_bytes(bytes.try_into().expect("SIZE bytes"))
            }
        }
    )*};
}
le_bytes!(f32, u32, u16, i16);

/// Little-endian bytes of `values`.
pub fn to_le<T: LeBytes>(values: impl IntoIterator<Item = T>) -> Vec<u8> {
    let mut out = Vec::new();
    for v in values {
        v.put(&mut out);
    }
    out
}

/// Values from little-endian `bytes` (a trailing partial value is ignored).
pub fn from_le<T: LeBytes>(bytes: &[u8]) -> Vec<T> {
    bytes.chunks_exact(T::SIZE).map(T::get).collect()
}

/// The tensor `name` of a safetensors file if it is there with dtype `dtype`; otherwise the
/// reason in words ("missing tensor NAME", "tensor NAME is U16, expected F32"), for the
/// caller to give with the file's path.
pub fn typed_tensor<'data>(
    st: &SafeTensors<'data>,
    name: &str,
    dtype: Dtype,
) -> Result<TensorView<'data>, String> {
    let t = st
        .tensor(name)
        .map_err(|_| format!("missing tensor {name}"))?;
    if t.dtype() != dtype {
        return Err(format!(
            "tensor {name} is {:?}, expected {dtype:?}",
            t.dtype()
        ));
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips() {
        let f = [1.5f32, -0.0, f32::MAX, 1e-30];
        assert_eq!(from_le::<f32>(&to_le(f)), f);
        let i = [-3i16, 7, i16::MIN];
        assert_eq!(from_le::<i16>(&to_le(i)), i);
        assert_eq!(to_le([0x0102u16]), vec![2, 1]);
    }

    #[test]
    fn typed_tensor_checks_name_and_dtype() {
        let data = to_le([1.0f32, 2.0]);
        let view = TensorView::new(Dtype::F32, vec![2], &data).unwrap();
        let bytes = safetensors::serialize([("x", view)], None).unwrap();
        let st = SafeTensors::deserialize(&bytes).unwrap();
        let x = typed_tensor(&st, "x", Dtype::F32).unwrap();
        assert_eq!(from_le::<f32>(x.data()), [1.0, 2.0]);
        assert_eq!(
            typed_tensor(&st, "x", Dtype::U32).unwrap_err(),
            "tensor x is F32, expected U32"
        );
        assert_eq!(
            typed_tensor(&st, "y", Dtype::F32).unwrap_err(),
            "missing tensor y"
        );
    }
}
