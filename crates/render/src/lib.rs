//! Headless CPU rendering for garnet: shaded pictures of bodies and garments.
//!
//! Everything here works on plain slices so the crate stays independent of the rest of the
//! workspace. Conventions follow the project: metres, right-handed, **Y up**, the body facing
//! **+Z**; faces are counter-clockwise seen from outside.
//!
//! - [`RenderMesh`]: one mesh of a scene (vertices `[N]` of [`glam::Vec3`], faces `[F]` of
//!   `[u32; 3]`, a base colour, optional per-vertex or per-face colours for heat maps).
//! - [`render_view`], [`render_views`], [`render_views_with`], [`render_panels`]: orthographic,
//!   smooth-shaded, two-sided, supersampled pictures; every view of one call shares one scale so
//!   front and side line up.
//! - [`Image`]: an RGB picture with atomic PNG writing ([`Image::save_png`]) and reading.
//! - [`Sheet`]: many pictures in a captioned grid; [`draw_text`] for labels.
//! - [`palette`]: garment and skin colours, the [`palette::heat`] colour ramp and a legend bar.
//! - [`page`]: self-contained HTML pages with a 3D view of GLB meshes (three.js embedded).

mod camera;
mod error;
mod image;
mod mesh;
mod occlusion;
pub mod page;
pub mod palette;
pub mod plot;
mod raster;
mod render;
mod shading;
mod sheet;
mod text;

pub use camera::{Framing, View};
pub use error::RenderError;
pub use image::Image;
pub use mesh::{RenderMesh, Shading};
pub use render::{render_panels, render_view, render_views, render_views_with, RenderOptions};
pub use sheet::{CaptionPlace, Sheet};
pub use text::{draw_text, text_size, GLYPH_SIZE};

#[cfg(test)]
mod test_util;
