//! `garnet assets`: fetch, convert and locate the body assets.

use clap::Subcommand;

/// Asset management.
#[derive(Subcommand, Debug)]
pub enum AssetsCmd {
    /// Download (pip), verify and convert the body assets now; prints where they are.
    Fetch,
    /// Print the cache directory and the converted body file (fetching if needed).
    Path,
}

pub fn run(cmd: &AssetsCmd) -> anyhow::Result<()> {
    match cmd {
        AssetsCmd::Fetch | AssetsCmd::Path => {
            let cache = body::assets::ensure_body_cache()?;
            let model = body::BodyModel::from_file(&cache)?;
            println!("garnet home: {}", body::assets::garnet_home().display());
            println!("body file:   {}", cache.display());
            println!(
                "body model:  {} bones, {} macro targets",
                model.bones().len(),
                model.target_names().count()
            );
            Ok(())
        }
    }
}
