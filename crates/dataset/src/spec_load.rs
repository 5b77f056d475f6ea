//! Reading a spec file: its format version, its `base` spec, and the overrides of the
//! poses per body (from a spec's `[poses_per_body]` table or the command line).
//!
//! A spec may name another as its `base` (a path relative to its own folder): the base is
//! read (with its own base, if any), then this file's keys replace the base's, table by
//! table (`[simulator]` keys one by one; an array such as `[[garments]]` as a whole). A
//! spec with a base may also give a `[poses_per_body]` table, garment name -> samples per
//! body, replacing those of the base's garments:
//!
//! ```toml
//! format = 2
//! base = "standard-lbs.toml"
//! name = "standard-x9-lbs"
//! [poses_per_body]
//! tshirt = 36
//! ```

use std::path::{Path, PathBuf};

use crate::error::{DatasetError, Result};

/// The spec format this version reads and writes (the top-level `format` key).
pub const SPEC_FORMAT: i64 = 2;

/// Most specs in a chain of bases.
const MAX_BASES: usize = 8;

/// The table of the spec `text` (read from `path`) with its base resolved: the merged
/// table, and whether a base was merged (its values then have no line in `text`).
pub(crate) fn resolve(text: &str, path: &Path) -> Result<(toml::Table, bool)> {
    resolve_chain(text, path, &mut Vec::new())
}

fn resolve_chain(text: &str, path: &Path, seen: &mut Vec<PathBuf>) -> Result<(toml::Table, bool)> {
    let mut table: toml::Table =
        toml::from_str(text).map_err(|e| crate::spec::toml_error(path, text, e))?;
    check_format(&table, path)?;
    let Some(base) = table.remove("base") else {
        if table.contains_key("poses_per_body") {
            return Err(DatasetError::spec(
                path,
                "poses_per_body",
                "only a spec with a `base` overrides the poses per body in a table; give \
                 each garment its `poses_per_body`",
            ));
        }
        return Ok((table, false));
    };
    let Some(base) = base.as_str() else {
        return Err(DatasetError::spec(
            path,
            "base",
            "must be the path of a spec file (relative to this one's folder)",
        ));
    };
    let base_path = path.parent().unwrap_or(Path::new("")).join(base);
    seen.push(path.to_path_buf());
    if seen.len() > MAX_BASES || seen.contains(&base_path) {
        return Err(DatasetError::spec(
            path,
            "base",
            format!(
                "'{base}' makes a chain of more than {MAX_BASES} specs or a cycle; name a \
                 spec without a base"
            ),
        ));
    }
    let base_text =
        std::fs::read_to_string(&base_path).map_err(|e| DatasetError::io(&base_path, e))?;
    let (mut merged, _) = resolve_chain(&base_text, &base_path, seen)?;
    let poses = table.remove("poses_per_body");
    merge(&mut merged, table);
    if let Some(poses) = poses {
        let Some(poses) = poses.as_table() else {
            return Err(DatasetError::spec(
                path,
                "poses_per_body",
                "must be a table of garment name = samples per body",
            ));
        };
        for (name, n) in poses {
            let field = format!("poses_per_body.{name}");
            let n = n
                .as_integer()
                .and_then(|n| u32::try_from(n).ok())
                .ok_or_else(|| DatasetError::spec(path, &field, "must be a whole number"))?;
            set_poses(&mut merged, name, n).map_err(|m| DatasetError::spec(path, &field, m))?;
        }
    }
    Ok((merged, true))
}

/// Errors unless `table` says `format = SPEC_FORMAT`, telling what to change.
fn check_format(table: &toml::Table, path: &Path) -> Result<()> {
    const WHAT_CHANGED: &str = "a spec of format 2 gets the simulator's and the garments' \
        current defaults where it names nothing (linear blend skinning, the jeans' \
        waistband, each kind's default cut); format 1 (no `format` key) meant dual \
        quaternion skinning, no waistband and the first cut. To keep a format-1 spec's \
        drapes, give `skinning = \"dqs\"` and `waistband = false` under [simulator] and each \
        garment the first cut (as specs/standard-lbs.toml does), then add `format = 2`";
    match table.get("format").map(toml::Value::as_integer) {
        Some(Some(SPEC_FORMAT)) => Ok(()),
        None => Err(DatasetError::spec(
            path,
            "format",
            format!("missing: add `format = {SPEC_FORMAT}` at the top; {WHAT_CHANGED}"),
        )),
        Some(Some(v)) if v < SPEC_FORMAT => Err(DatasetError::spec(
            path,
            "format",
            format!("format {v} is no longer read; {WHAT_CHANGED}"),
        )),
        _ => Err(DatasetError::spec(
            path,
            "format",
            format!("this garnet reads spec format {SPEC_FORMAT} only"),
        )),
    }
}

/// Merges `over` into `base`: tables key by key (recursively), any other value replaced.
fn merge(base: &mut toml::Table, over: toml::Table) {
    for (key, value) in over {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) => merge(b, o),
            (_, value) => {
                base.insert(key, value);
            }
        }
    }
}

/// Sets `poses_per_body = n` on the garment called `name` (its `name`, else its `kind`) of
/// the spec table; errors name the garments there are.
fn set_poses(table: &mut toml::Table, name: &str, n: u32) -> std::result::Result<(), String> {
    let garments = table
        .get_mut("garments")
        .and_then(toml::Value::as_array_mut);
    let mut names = Vec::new();
    for g in garments.into_iter().flatten() {
        let Some(g) = g.as_table_mut() else { continue };
        let own = g
            .get("name")
            .or_else(|| g.get("kind"))
            .and_then(toml::Value::as_str)
            .unwrap_or_default()
            .to_string();
        if own == name {
            g.insert("poses_per_body".into(), toml::Value::Integer(n.into()));
            return Ok(());
        }
        names.push(own);
    }
    Err(format!(
        "no garment '{name}' (the garments are {})",
        names.join(", ")
    ))
}

/// Parses a poses override `GARMENT=N[,GARMENT=N]` (`tshirt=99,sweater=54`) into
/// `(garment, samples per body)` pairs; errors say what is wrong with which part.
pub fn parse_poses_override(text: &str) -> Result<Vec<(String, u32)>> {
    let bad = |part: &str, why: &str| {
        DatasetError::Invalid(format!(
            "--poses '{text}': '{part}' {why} (expected GARMENT=N[,GARMENT=N], e.g. tshirt=99)"
        ))
    };
    let mut out: Vec<(String, u32)> = Vec::new();
    for part in text.split(',').map(str::trim) {
        let (name, n) = part
            .split_once('=')
            .ok_or_else(|| bad(part, "has no '='"))?;
        let n: u32 = n
            .trim()
            .parse()
            .map_err(|_| bad(part, "does not end in a whole number"))?;
        if n == 0 {
            return Err(bad(part, "asks for no pose"));
        }
        let name = name.trim();
        if out.iter().any(|(g, _)| g == name) {
            return Err(bad(part, "names its garment twice"));
        }
        out.push((name.to_string(), n));
    }
    Ok(out)
}

/// The spec table `table` with `overrides` applied (see [`parse_poses_override`]); errors
/// name `path` and the unknown garment.
pub(crate) fn override_poses(
    table: &mut toml::Table,
    overrides: &[(String, u32)],
    path: &Path,
) -> Result<()> {
    for (name, n) in overrides {
        set_poses(table, name, *n)
            .map_err(|m| DatasetError::spec(path, format!("--poses {name}={n}"), m))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_merge_and_other_values_replace() {
        let mut base: toml::Table =
            toml::from_str("a = 1\n[t]\nx = 1\ny = 2\n[[g]]\nk = 1\n").unwrap();
        merge(
            &mut base,
            toml::from_str("a = 3\n[t]\ny = 5\n[[g]]\nk = 9\n").unwrap(),
        );
        let want: toml::Table = toml::from_str("a = 3\n[t]\nx = 1\ny = 5\n[[g]]\nk = 9\n").unwrap();
        assert_eq!(base, want);
    }

    #[test]
    fn poses_overrides_parse_or_say_what_is_wrong() {
        assert_eq!(
            parse_poses_override("tshirt=99, jeans = 4").unwrap(),
            [("tshirt".to_string(), 99), ("jeans".to_string(), 4)]
        );
        for (bad, why) in [
            ("tshirt", "no '='"),
            ("tshirt=x", "whole number"),
            ("tshirt=0", "no pose"),
            ("a=1,a=2", "twice"),
        ] {
            let e = parse_poses_override(bad).unwrap_err().to_string();
            assert!(e.contains(why) && e.contains("GARMENT=N"), "{e}");
        }
    }

    #[test]
    fn a_spec_without_the_format_says_what_to_add() {
        let p = Path::new("s.toml");
        let e = resolve("seed = 1\n", p).unwrap_err().to_string();
        assert!(
            e.starts_with("s.toml: format: missing: add `format = 2`"),
            "{e}"
        );
        let e = resolve("format = 1\n", p).unwrap_err().to_string();
        assert!(
            e.contains("format 1 is no longer read") && e.contains("dqs"),
            "{e}"
        );
        let e = resolve("format = 2\n[poses_per_body]\ntshirt = 3\n", p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("only a spec with a `base`"), "{e}");
    }
}
