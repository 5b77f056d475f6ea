//! Writing meshes and pictures for the commands.

use std::path::Path;

use anyhow::Context;
use geom::TriMesh;
use render::{RenderMesh, View};

/// Writes `mesh` to `path` in the format its extension names (.obj, .ply, .glb).
pub fn write_mesh(path: &Path, mesh: &TriMesh) -> anyhow::Result<()> {
    create_parent(path)?;
    geom::io::write_mesh(path, mesh).with_context(|| format!("writing {}", path.display()))?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

/// Renders the front and side views of `meshes` (`(mesh, colour)`) at `size` pixels
/// per view and saves a PNG.
pub fn write_png(
    path: &Path,
    meshes: &[(&TriMesh, [u8; 3])],
    size: (u32, u32),
) -> anyhow::Result<()> {
    save_png(path, &render_views(meshes, size)?)
}

/// Saves `image` as a PNG at `path` (creating its folder) and says so.
pub fn save_png(path: &Path, image: &render::Image) -> anyhow::Result<()> {
    create_parent(path)?;
    image
        .save_png(path)
        .with_context(|| format!("writing {}", path.display()))?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

/// Front and side views of `meshes` side by side.
pub fn render_views(
    meshes: &[(&TriMesh, [u8; 3])],
    size: (u32, u32),
) -> anyhow::Result<render::Image> {
    let scene: Vec<RenderMesh> = meshes
        .iter()
        .map(|(m, c)| RenderMesh::new(&m.vertices, &m.faces, *c))
        .collect();
    Ok(render::render_views(
        &scene,
        &[View::Front, View::Side],
        size,
    )?)
}

/// Strain at which the strain map is red, percent.
pub const STRAIN_MAP_MAX_PCT: f32 = 10.0;

/// Saves a strain map: front, side and back views (`size` pixels each) of the body in skin
/// colour and the garment coloured by `vertex_strain` (`[N]`, 0.01 = 1%: blue at 0 or less,
/// red at [`STRAIN_MAP_MAX_PCT`] or more), with a legend.
pub fn write_strain_png(
    path: &Path,
    body: &TriMesh,
    garment: &TriMesh,
    vertex_strain: &[f32],
    size: (u32, u32),
) -> anyhow::Result<()> {
    let colors = render::palette::heat_colors(vertex_strain, 0.0, STRAIN_MAP_MAX_PCT / 100.0);
    let scene = [
        RenderMesh::new(&body.vertices, &body.faces, render::palette::SKIN),
        RenderMesh::new(&garment.vertices, &garment.faces, [0; 3]).with_vertex_colors(&colors),
    ];
    let mut image = render::render_views(&scene, &[View::Front, View::Side, View::Back], size)?;
    let legend = render::palette::heat_legend(
        size.0 / 2,
        "strain 0%",
        &format!("{STRAIN_MAP_MAX_PCT:.0}%"),
    );
    image.blit(&legend, 16, 16);
    save_png(path, &image)
}

/// Creates the parent directory of `path` if it is missing.
pub fn create_parent(path: &Path) -> anyhow::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    Ok(())
}
