//! `garnet pose`: pose file utilities.

use std::path::PathBuf;

use body::pose::{save_bvh, Amc, Asf, BvhWriteOptions};
use clap::Subcommand;

/// Pose file utilities.
#[derive(Subcommand, Debug)]
pub enum PoseCmd {
    /// Convert a CMU ASF/AMC clip to a CMU-style BVH file (same joint names and units).
    Convert {
        /// The clip's skeleton.
        #[arg(long)]
        asf: PathBuf,
        /// The clip.
        #[arg(long)]
        amc: PathBuf,
        /// The BVH file to write.
        #[arg(long)]
        out: PathBuf,
    },
}

pub fn run(cmd: &PoseCmd) -> anyhow::Result<()> {
    match cmd {
        PoseCmd::Convert { asf, amc, out } => {
            let skeleton = Asf::read(asf)?;
            let clip = Amc::read(amc, &skeleton)?;
            crate::output::create_parent(out)?;
            save_bvh(out, &skeleton, &clip, &BvhWriteOptions::default())?;
            eprintln!("wrote {} ({} frames)", out.display(), clip.frame_count());
            Ok(())
        }
    }
}
