//! Garments for garnet: T-shirt, sweater and jeans templates fitted on the template
//! body, with cut parameters, UVs and skinning weights, imported user garments, and
//! dual quaternion skinning (DQS) of a template onto any body shape and pose.

pub mod build;
pub mod cut;
pub mod error;
pub mod import;
pub mod inflate;
pub mod region;
pub mod template;
pub mod uv;
pub mod waistband;
pub mod warp;
pub mod weights;

pub use build::build_template;
pub use cut::{CutParams, GarmentKind};
pub use error::GarmentError;
pub use template::GarmentTemplate;
