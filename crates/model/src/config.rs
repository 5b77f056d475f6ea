//! Network configuration: the variant and every width the paper leaves open.
//!
//! The defaults are the widths documented in the crate docs (and `docs/model.md`); they were
//! chosen so that GarNet-Local drapes a ~10k-vertex garment on the 13380-vertex body in
//! well under 150 ms on 2 CPU cores while keeping the paper's structure (512-d body features,
//! 8-head FeaStNet convolutions, 6 residual blocks, 15/16-neighbour pooling, 10x body
//! downsampling).

use burn::prelude::*;

use crate::error::{ModelError, Result};

/// Which of the paper's three networks.
#[derive(Config, Debug, Copy, PartialEq, Eq, Hash)]
pub enum Variant {
    /// GarNet-Naive: a two-stream PointNet; no mesh convolution, no local body features.
    Naive,
    /// GarNet-Global: mesh convolutions in the garment stream, global body features only.
    Global,
    /// GarNet-Local: GarNet-Global plus, per garment vertex, the max-pooled features of its
    /// 15 nearest (10x downsampled) body points.
    Local,
}

impl Variant {
    /// The three variants, in the paper's order of Table 1 (best first).
    pub const ALL: [Variant; 3] = [Variant::Local, Variant::Global, Variant::Naive];

    /// Lower-case name: `naive`, `global` or `local`.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Naive => "naive",
            Variant::Global => "global",
            Variant::Local => "local",
        }
    }

    /// Parses [`Variant::name`] (case-insensitive; `garnet-` prefix allowed).
    pub fn parse(s: &str) -> Result<Variant> {
        let lower = s.to_ascii_lowercase();
        match lower.trim_start_matches("garnet-") {
            "naive" => Ok(Variant::Naive),
            "global" => Ok(Variant::Global),
            "local" => Ok(Variant::Local),
            _ => Err(ModelError::InvalidInput(format!(
                "unknown GarNet variant {s:?} (naive, global or local)"
            ))),
        }
    }

    /// Whether the garment stream has the FeaStNet mesh-convolution blocks.
    pub fn has_mesh_conv(self) -> bool {
        self != Variant::Naive
    }

    /// Whether the fusion network gets pooled local body features.
    pub fn has_local(self) -> bool {
        self == Variant::Local
    }
}

/// What the network's input M (the base its translations are added to) is.
#[derive(Config, Debug, Copy, PartialEq, Eq, Hash)]
pub enum Base {
    /// The paper's M: the garment template skinned onto the posed body by dual quaternions,
    /// driven by the joints only.
    Dqs,
    /// The garment template placed on the posed body's surface by its surface anchors (each
    /// vertex keeps its offset in the frame of its closest template-body surface point): the
    /// state the fitted-start simulator starts from, so M follows girth as well as pose.
    Anchored,
}

impl Base {
    /// Lower-case name: `dqs` or `anchored`.
    pub fn name(self) -> &'static str {
        match self {
            Base::Dqs => "dqs",
            Base::Anchored => "anchored",
        }
    }

    /// Parses [`Base::name`] (case-insensitive).
    pub fn parse(s: &str) -> Result<Base> {
        match s.to_ascii_lowercase().as_str() {
            "dqs" => Ok(Base::Dqs),
            "anchored" => Ok(Base::Anchored),
            _ => Err(ModelError::InvalidInput(format!(
                "unknown base {s:?} (dqs or anchored)"
            ))),
        }
    }
}

/// GarNet's architecture: variant and widths (channel counts). `init` builds the network.
///
/// Every list is the output widths of the consecutive per-point layers of one block; each
/// layer is a shared fully connected layer followed by LeakyReLU(0.1).
#[derive(Config, Debug, PartialEq)]
pub struct GarNetConfig {
    /// Which network.
    pub variant: Variant,
    /// The body stream sees every `body_subsample`-th body point (a fixed farthest-point
    /// subset, see [`crate::local::BodySampling`]): 4 gives 3345 of the 13380 body vertices
    /// (a training step 2.1x faster than with 2, measured on 2 cores), 2 gives 6690, about
    /// the paper's SMPL point count (6890). 1 uses every vertex.
    #[config(default = 4)]
    pub body_subsample: usize,
    /// Per-point MLP of every spatial transformer network (STN), before its max pooling.
    #[config(default = "vec![32, 64, 128]")]
    pub stn_mlp: Vec<usize>,
    /// Fully connected layers of every STN after the pooling (then a zero-initialised layer
    /// to the k x k matrix, added to the identity).
    #[config(default = "vec![64]")]
    pub stn_fc: Vec<usize>,
    /// Body stream, first MLP block (after the 3x3 input STN); its output gets the 64x64-style
    /// feature STN (k = last width).
    #[config(default = "vec![64, 64]")]
    pub body_mlp1: Vec<usize>,
    /// Body stream, second MLP block; its input is the feature-transformed first block
    /// concatenated with the input STN's output (the paper's skip). The last width is the
    /// point-wise body feature width and, max-pooled, the global body feature (512 in the
    /// paper).
    #[config(default = "vec![128, 512]")]
    pub body_mlp2: Vec<usize>,
    /// Local variant: width of the pooled local body feature (a shared layer maps the
    /// average-pooled 512-d body features to this before the 15-neighbour max pooling).
    #[config(default = 64)]
    pub local_width: usize,
    /// Local variant: downsampling factor of the body stream points (10 in the paper).
    #[config(default = 10)]
    pub body_downsample: usize,
    /// Local variant: body stream points averaged into each downsampled point (16 in the
    /// paper).
    #[config(default = 16)]
    pub pool_neighbours: usize,
    /// Local variant: downsampled body points max-pooled per garment vertex (15 in the
    /// paper).
    #[config(default = 15)]
    pub local_neighbours: usize,
    /// Garment stream point-wise MLP (after the 3x3 STN on M); the global body feature
    /// enters every layer (as a per-sample bias). The last width is the point-wise garment
    /// feature width.
    #[config(default = "vec![64, 64]")]
    pub garment_mlp: Vec<usize>,
    /// Width of the mesh-convolution features (the patch-wise garment feature width).
    #[config(default = 32)]
    pub conv_width: usize,
    /// FeaStNet heads M (8, FeaStNet's default).
    #[config(default = 8)]
    pub conv_heads: usize,
    /// Residual mesh-convolution blocks (6 in the paper).
    #[config(default = 6)]
    pub conv_blocks: usize,
    /// FeaStNet convolutions per residual block (the paper does not say; each one's input is
    /// the features concatenated with the vertex positions).
    #[config(default = 1)]
    pub convs_per_block: usize,
    /// Our extension (not in the paper): the garment stream's point-wise MLP also takes, per
    /// vertex of M, the offset to the nearest body vertex, that vertex's normal and the signed
    /// distance (see [`crate::contact`]). Off in the paper's networks.
    #[config(default = false)]
    pub body_contact: bool,
    /// Our extension (not in the paper): the garment stream's point-wise MLP also takes each
    /// vertex's position on the template (the same for every sample), so the network knows
    /// which vertex it is looking at whatever the pose. Off in the paper's networks.
    #[config(default = false)]
    pub rest_input: bool,
    /// Our extension (not in the paper): what M is. [`Base::Dqs`] is the paper's; whoever
    /// drapes with the network builds M as this says (see `garnet::base_anchors`).
    #[config(default = "Base::Dqs")]
    pub base: Base,
    /// Width of the global garment feature (a shared layer then max pooling over vertices).
    #[config(default = 256)]
    pub garment_global: usize,
    /// Hidden widths of the fusion network; a last layer maps to the 3 translation
    /// components, so three hidden widths make the paper's four MLP blocks.
    #[config(default = "vec![128, 64, 32]")]
    pub fusion: Vec<usize>,
    /// Length unit of the network's inputs and outputs, metres: positions enter as
    /// `(p - input_centre) / input_scale` and the predicted translations leave multiplied by
    /// it. In metres (1.0) the per-vertex part of every feature is hundreds of times smaller
    /// than the per-sample body feature added to it, and the network cannot tell the garment's
    /// vertices apart (see docs/model.md); 0.1 gives unit-sized inputs.
    #[config(default = 0.1)]
    pub input_scale: f32,
    /// Centre subtracted from every input position (metres, the canonical frame):
    /// [`crate::ModelSetup::new`] sets the garment template's centroid.
    #[config(default = "vec![0.0, 0.0, 0.0]")]
    pub input_centre: Vec<f32>,
    /// Seed of the initial parameter values.
    #[config(default = 0)]
    pub seed: u64,
}

impl GarNetConfig {
    /// A very small network of `variant` for tests and quick experiments (same structure,
    /// narrow layers, 2 residual blocks, 4 heads).
    pub fn tiny(variant: Variant) -> Self {
        GarNetConfig::new(variant)
            .with_stn_mlp(vec![16, 32])
            .with_stn_fc(vec![16])
            .with_body_mlp1(vec![16, 16])
            .with_body_mlp2(vec![32, 64])
            .with_local_width(16)
            .with_body_subsample(2)
            .with_body_downsample(4)
            .with_pool_neighbours(4)
            .with_local_neighbours(3)
            .with_garment_mlp(vec![32, 32])
            .with_conv_width(16)
            .with_conv_heads(4)
            .with_conv_blocks(2)
            .with_garment_global(32)
            .with_fusion(vec![64, 32, 16])
    }

    /// Fails when a width list is empty or a width, head count or neighbour count is 0.
    pub fn validate(&self) -> Result<()> {
        let lists = [
            ("stn_mlp", &self.stn_mlp),
            ("stn_fc", &self.stn_fc),
            ("body_mlp1", &self.body_mlp1),
            ("body_mlp2", &self.body_mlp2),
            ("garment_mlp", &self.garment_mlp),
            ("fusion", &self.fusion),
        ];
        for (name, list) in lists {
            if list.is_empty() || list.contains(&0) {
                return Err(ModelError::InvalidInput(format!(
                    "config {name} must be a non-empty list of positive widths, got {list:?}"
                )));
            }
        }
        let counts = [
            ("local_width", self.local_width),
            ("body_subsample", self.body_subsample),
            ("body_downsample", self.body_downsample),
            ("pool_neighbours", self.pool_neighbours),
            ("local_neighbours", self.local_neighbours),
            ("conv_width", self.conv_width),
            ("conv_heads", self.conv_heads),
            ("garment_global", self.garment_global),
        ];
        for (name, v) in counts {
            if v == 0 {
                return Err(ModelError::InvalidInput(format!(
                    "config {name} must be positive"
                )));
            }
        }
        if !(self.input_scale.is_finite() && self.input_scale > 0.0)
            || self.input_centre.len() != 3
            || self.input_centre.iter().any(|c| !c.is_finite())
        {
            return Err(ModelError::InvalidInput(format!(
                "config input_scale must be positive and input_centre 3 finite numbers, got \
                 {} and {:?}",
                self.input_scale, self.input_centre
            )));
        }
        if self.variant.has_mesh_conv() && (self.conv_blocks == 0 || self.convs_per_block == 0) {
            return Err(ModelError::InvalidInput(
                "GarNet-Global and -Local need at least one mesh-convolution block".into(),
            ));
        }
        Ok(())
    }

    /// The network's name in reports: `GarNet-local` (the variant's name), followed by
    /// ` +contact`, ` +rest`, ` +norm` and ` +anchored` when it has our extensions.
    pub fn method_name(&self) -> String {
        let mut name = format!("GarNet-{}", self.variant.name());
        if self.body_contact {
            name.push_str(" +contact");
        }
        if self.rest_input {
            name.push_str(" +rest");
        }
        if self.base == Base::Anchored {
            name.push_str(" +anchored");
        }
        name
    }

    /// Width of the point-wise (and global) body features.
    pub fn body_feature_width(&self) -> usize {
        *self.body_mlp2.last().unwrap_or(&0)
    }

    /// Width of the point-wise garment features.
    pub fn garment_point_width(&self) -> usize {
        *self.garment_mlp.last().unwrap_or(&0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_names_say_the_variant_and_the_extensions() {
        assert_eq!(
            GarNetConfig::new(Variant::Local).method_name(),
            "GarNet-local"
        );
        let both = GarNetConfig::new(Variant::Global)
            .with_body_contact(true)
            .with_rest_input(true);
        assert_eq!(both.method_name(), "GarNet-global +contact +rest");
        assert_eq!(
            both.clone().with_body_contact(false).method_name(),
            "GarNet-global +rest"
        );
        assert_eq!(
            both.with_base(Base::Anchored).method_name(),
            "GarNet-global +contact +rest +anchored"
        );
        assert_eq!(Base::parse("Anchored").unwrap(), Base::Anchored);
        assert_eq!(Base::parse(Base::Dqs.name()).unwrap(), Base::Dqs);
    }
}
