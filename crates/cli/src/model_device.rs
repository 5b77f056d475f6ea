//! Choosing where a GarNet network runs (`--device`).

use burn::prelude::Device;
use clap::ValueEnum;

/// Where the network runs: the CPU (burn's `flex` backend, always built in), the first CUDA
/// GPU (needs `garnet` built with `--features cuda`) or the best GPU Vulkan finds (needs
/// `--features vulkan`).
#[derive(ValueEnum, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum DeviceArg {
    /// CPU, all cores (burn flex).
    #[default]
    Cpu,
    /// The first NVIDIA GPU (burn cuda).
    Cuda,
    /// The best GPU that Vulkan offers (burn wgpu, SPIR-V shaders).
    Vulkan,
}

impl DeviceArg {
    /// The burn backend this device runs on, in words ("flex CPU backend").
    pub fn backend_name(self) -> &'static str {
        match self {
            DeviceArg::Cpu => "flex CPU backend",
            DeviceArg::Cuda => "cuda GPU backend",
            DeviceArg::Vulkan => "vulkan GPU backend",
        }
    }

    /// The burn device; an error when this build does not include the backend.
    pub fn device(self) -> anyhow::Result<Device> {
        match self {
            DeviceArg::Cpu => Ok(Device::flex()),
            #[cfg(feature = "cuda")]
            DeviceArg::Cuda => probe(Device::cuda(0), "CUDA"),
            #[cfg(not(feature = "cuda"))]
            DeviceArg::Cuda => anyhow::bail!(
                "this garnet was built without CUDA: rebuild with `cargo build --release --features cuda`"
            ),
            #[cfg(feature = "vulkan")]
            DeviceArg::Vulkan => probe(
                Device::vulkan(burn::tensor::DeviceKind::DefaultDevice),
                "Vulkan",
            ),
            #[cfg(not(feature = "vulkan"))]
            DeviceArg::Vulkan => anyhow::bail!(
                "this garnet was built without Vulkan: rebuild with `cargo build --release --features vulkan`"
            ),
        }
    }
}

/// Reads one value back from `device`. The GPU runtimes panic, in a thread of their own, when
/// they find no driver or adapter (seen on a machine whose Vulkan loader could not use the
/// NVIDIA driver); that becomes an error naming the backend instead.
#[cfg(any(feature = "cuda", feature = "vulkan"))]
fn probe(device: Device, backend: &str) -> anyhow::Result<Device> {
    let d = device.clone();
    // The runtime's own panic message would only repeat the error below.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let answered = std::panic::catch_unwind(move || {
        burn::tensor::Tensor::<1>::from_floats([1.0f32], &d).into_data()
    });
    std::panic::set_hook(hook);
    match answered {
        Ok(_) => Ok(device),
        Err(_) => anyhow::bail!(
            "no {backend} GPU answered: check the driver (for Vulkan, the loader libvulkan1 and \
             VK_DRIVER_FILES naming the vendor's ICD file)"
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_is_always_built_in() {
        assert!(DeviceArg::Cpu.device().is_ok());
    }

    #[cfg(not(feature = "cuda"))]
    #[test]
    fn cuda_without_the_feature_says_how_to_build_it() {
        let e = DeviceArg::Cuda.device().unwrap_err().to_string();
        assert!(e.contains("--features cuda"), "{e}");
    }

    #[cfg(not(feature = "vulkan"))]
    #[test]
    fn vulkan_without_the_feature_says_how_to_build_it() {
        let e = DeviceArg::Vulkan.device().unwrap_err().to_string();
        assert!(e.contains("--features vulkan"), "{e}");
    }
}
