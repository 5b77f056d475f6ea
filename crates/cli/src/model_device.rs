//! Choosing where a GarNet network runs (`--device`).

use burn::prelude::Device;
use clap::ValueEnum;

/// Where the network runs: the CPU (burn's `flex` backend, always built in) or the first
/// CUDA GPU (needs `garnet` built with `--features cuda`).
#[derive(ValueEnum, Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum DeviceArg {
    /// CPU, all cores (burn flex).
    #[default]
    Cpu,
    /// The first NVIDIA GPU (burn cuda).
    Cuda,
}

impl DeviceArg {
    /// The burn device; an error when this build does not include the backend.
    pub fn device(self) -> anyhow::Result<Device> {
        match self {
            DeviceArg::Cpu => Ok(Device::flex()),
            #[cfg(feature = "cuda")]
            DeviceArg::Cuda => Ok(Device::cuda(0)),
            #[cfg(not(feature = "cuda"))]
            DeviceArg::Cuda => anyhow::bail!(
                "this garnet was built without CUDA: rebuild with `cargo build --release --features cuda`"
            ),
        }
    }
}
