//! Allocator tuning for tensor work on the CPU.
//!
//! A GarNet forward pass allocates and frees temporaries of 2-15 MB (per-vertex aggregations,
//! 512-wide body features). glibc's malloc serves blocks above its mmap threshold (128 kB at
//! first, adapting up to 32 MB) with fresh `mmap`s and returns them with `munmap`, so every
//! such temporary is paid again in page faults: measured here, the FeaStNet aggregation of a
//! 10k-vertex garment took 17 ms with the default settings and 5 ms with the threshold raised.
//! [`tune_allocator`] raises the mmap threshold to glibc's maximum (32 MB) and the trim
//! threshold to 512 MB, so that freed blocks are reused instead of returned to the system.
//! The cost is that the process keeps up to its peak heap (hundreds of MB while training on
//! 10k-vertex garments). It changes the whole process's allocator, so the libraries never
//! call it: a program calls it once at its start (the `garnet` binary does, as do the Python
//! package and the library's examples); a program with another global allocator (mimalloc,
//! jemalloc) is not affected.

use std::sync::OnceLock;

static APPLIED: OnceLock<bool> = OnceLock::new();

/// Largest mmap threshold glibc accepts on 64-bit targets (`DEFAULT_MMAP_THRESHOLD_MAX`).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const MMAP_THRESHOLD: i32 = 32 * 1024 * 1024;

/// Free memory at the top of the heap kept before it is returned to the system.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const TRIM_THRESHOLD: i32 = 512 * 1024 * 1024;

/// Applies the settings above once per process (later calls do nothing). Returns whether
/// they are in effect: `true` on glibc Linux when malloc accepted them, `false` elsewhere.
pub fn tune_allocator() -> bool {
    *APPLIED.get_or_init(apply)
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn apply() -> bool {
    // SAFETY: mallopt only changes malloc's tuning parameters; it is thread-safe in glibc.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_THRESHOLD) == 1
            && libc::mallopt(libc::M_TRIM_THRESHOLD, TRIM_THRESHOLD) == 1
    }
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn apply() -> bool {
    false
}

#[cfg(test)]
mod tests {
    #[test]
    fn tuning_applies_once_on_glibc() {
        let first = super::tune_allocator();
        assert_eq!(first, super::tune_allocator());
        assert_eq!(first, cfg!(all(target_os = "linux", target_env = "gnu")));
    }
}
