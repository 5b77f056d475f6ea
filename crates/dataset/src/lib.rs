//! GarNet datasets: generation and reading (see DESIGN.md section 7).
//!
//! A TOML [`spec`] names the garments, the body-shape distribution, the pose sources,
//! the counts, the seed, the splits and the simulator settings. The [`plan`] enumerates
//! every sample from the seed alone; [`generate`](mod@generate) drapes them in parallel into
//! safetensors [`shard`]s (a fixed range of sample indices each, byte-identical whatever
//! the number of jobs, the interruptions or the `--shard i/n` split of the work) with a
//! JSON [`manifest`]; generation resumes where it stopped; [`merge`](mod@merge) joins the folders
//! of a job array; [`spread`](mod@spread) measures how repeatable the simulator's drapes of a
//! spec are. [`reader::Dataset`] reads samples back with checksums verified, and
//! [`batches`] streams shuffled batches of a split without loading the dataset.
//!
//! Units: metres, Y up, the body facing +Z. Per sample: the posed body `[V,3]`, the
//! warped template M `[N,3]` (the paper's joint-only DQS), the draped garment G `[N,3]`,
//! the phenotype `[11]` and the pose (root translation, `[B]` quaternions).

#![warn(missing_docs)]

pub mod batches;
pub mod body_faces;
pub mod cache;
pub mod cuts;
pub mod error;
pub mod generate;
pub mod hash;
pub mod layout;
pub mod manifest;
pub mod merge;
pub mod parts;
pub mod plan;
pub mod pool;
pub mod poses;
pub mod reader;
pub mod rebuild;
pub mod records;
pub mod reuse;
pub mod rng;
mod run;
pub mod sample;
pub mod selection;
pub mod shard;
pub mod simulator;
pub mod spec;
pub mod spec_check;
pub mod spec_load;
pub mod spread;
pub mod summary;
pub mod templates;
pub mod tensors;

pub use batches::{BatchOptions, Batches, Order};
pub use error::{DatasetError, Result};
pub use generate::{generate, GenerateOptions, GenerateReport, Progress};
pub use manifest::Manifest;
pub use merge::{merge, MergeReport};
pub use plan::Plan;
pub use reader::{Dataset, Sample};
pub use records::DrapeFilter;
pub use selection::ShardSelection;
pub use spec::{LoadedSpec, Spec};
pub use spread::{spread, SpreadOptions, SpreadReport};
pub use summary::Summary;
