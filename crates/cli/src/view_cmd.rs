//! `garnet view`: meshes (OBJ, PLY, GLB, animated GLB) and `garnet eval --save-drapes` folders
//! as one self-contained HTML page with a 3D view ([`render::page`]); and the page of
//! `garnet eval --html` (the report's tables, its charts and the worst drapes as heat maps).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use clap::Args;
use geom::io::{GlbMesh, MeshFormat};
use geom::TriMesh;
use render::page::{data_url, markdown_html, Legend, Page, PageMesh, Scene};
use render::palette;

use crate::output::create_parent;

/// Arguments of `garnet view`.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    /// Meshes to show together (.obj, .ply, .glb; animated GLBs of `garnet drape --frames`
    /// play), or a folder `DIR/MODEL` of `garnet eval --save-drapes DIR`: its sample
    /// `--sample` (the network's drape coloured by its distance to the simulator's, with the
    /// body and, hidden at first, the simulator's drape and the warped template).
    #[arg(required = true, num_args = 1.., value_name = "FILE")]
    pub files: Vec<PathBuf>,
    /// The HTML page to write (opens offline: three.js and the meshes are inside).
    #[arg(long, value_name = "HTML")]
    pub out: PathBuf,
    /// Sample index of a `--save-drapes` folder (default: its worst drape, by E_dist).
    #[arg(long, value_name = "INDEX")]
    pub sample: Option<u64>,
    /// Top of the heat maps' colour scale, cm (default: the largest distance shown).
    #[arg(long, value_name = "CM")]
    pub max_cm: Option<f32>,
    /// Page title (default: the file names).
    #[arg(long)]
    pub title: Option<String>,
}

/// Runs `garnet view`.
pub fn run(args: &ViewArgs) -> anyhow::Result<()> {
    if let Some(m) = args.max_cm {
        if !(m.is_finite() && m > 0.0) {
            bail!("--max-cm {m}: must be a positive number of centimetres");
        }
    }
    let mut meshes = Vec::new();
    let mut heat: Vec<HeatDrape> = Vec::new();
    let mut garments = 0;
    for file in &args.files {
        if file.is_dir() {
            let rows = read_samples(file)?;
            let index = match args.sample {
                Some(i) => i,
                None => worst(&rows, 1)[0].index,
            };
            if !rows.iter().any(|r| r.index == index) {
                bail!(
                    "{}: no sample {index} in samples.csv (it has {})",
                    file.display(),
                    describe_indices(&rows)
                );
            }
            heat.push(HeatDrape::read(file, index)?);
        } else {
            meshes.push(mesh_file(file, &mut garments)?);
        }
    }
    let mut legend = None;
    if !heat.is_empty() {
        let high = args.max_cm.unwrap_or_else(|| scale_top(&heat));
        for h in &heat {
            meshes.extend(h.page_meshes(high)?);
        }
        legend = Some(distance_legend(high));
    }
    let names: Vec<String> = args
        .files
        .iter()
        .map(|f| {
            if f.is_dir() {
                let sample = heat.iter().find(|h| h.dir == *f).map_or(0, |h| h.index);
                format!("{} sample {sample}", file_name(f))
            } else {
                file_name(f)
            }
        })
        .collect();
    let title = args
        .title
        .clone()
        .unwrap_or_else(|| format!("garnet view: {}", names.join(", ")));
    let page = Page {
        title: title.clone(),
        scenes: vec![Scene {
            title,
            meshes,
            legend,
        }],
        ..Page::default()
    };
    write_page(&args.out, &page)
}

/// Writes `page` to `path` (creating its folder) and says so.
fn write_page(path: &Path, page: &Page) -> anyhow::Result<()> {
    if path.is_dir() {
        bail!("{}: is a folder (--out takes an HTML file)", path.display());
    }
    create_parent(path)?;
    let html = page.html();
    geom::io::write_bytes_atomic(path, html.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    eprintln!(
        "wrote {} ({} KiB)",
        path.display(),
        html.len().div_ceil(1024)
    );
    Ok(())
}

fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// An sRGB colour as glTF's linear RGBA base colour.
fn rgba(c: [u8; 3]) -> [f32; 4] {
    let [r, g, b] = linear(c);
    [r, g, b, 1.0]
}

/// An sRGB colour in linear RGB (the sRGB transfer function), as glTF stores colours.
fn linear(c: [u8; 3]) -> [f32; 3] {
    c.map(|v| {
        let v = f32::from(v) / 255.0;
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    })
}

/// One mesh file as a page mesh: a GLB as it is (checked by reading it), OBJ and PLY as GLB
/// (bodies skin-coloured by name, garments in the palette's garment colours in turn).
fn mesh_file(path: &Path, garments: &mut usize) -> anyhow::Result<PageMesh> {
    if !path.exists() {
        bail!("{}: no such file", path.display());
    }
    let format = MeshFormat::from_path(path).with_context(|| {
        format!(
            "{}: not a mesh file garnet view reads (.obj, .ply, .glb, or a folder of garnet \
             eval --save-drapes)",
            path.display()
        )
    })?;
    let name = file_name(path);
    let glb = match format {
        MeshFormat::Glb => {
            let bytes =
                std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
            let prims = geom::io::parse_glb(&bytes, path)
                .with_context(|| format!("{}: not a readable GLB", path.display()))?;
            if prims.is_empty() {
                bail!("{}: the GLB holds no triangle mesh", path.display());
            }
            bytes
        }
        MeshFormat::Obj | MeshFormat::Ply => {
            let mesh = geom::io::read_mesh(path)
                .with_context(|| format!("{}: not a readable mesh", path.display()))?;
            let lower = name.to_ascii_lowercase();
            let color = if lower.contains("body") {
                palette::SKIN
            } else {
                *garments += 1;
                palette::GARMENTS[(*garments - 1) % palette::GARMENTS.len()]
            };
            encode(path, &mesh, &name, color, None)?
        }
    };
    Ok(PageMesh {
        name,
        glb,
        visible: true,
    })
}

/// `mesh` as GLB bytes with a base colour and optional per-vertex sRGB colours.
fn encode(
    path: &Path,
    mesh: &TriMesh,
    name: &str,
    color: [u8; 3],
    vertex_colors: Option<&[[u8; 3]]>,
) -> anyhow::Result<Vec<u8>> {
    let glb = [GlbMesh {
        mesh,
        name,
        color: rgba(color),
    }];
    let bytes = match vertex_colors {
        None => geom::io::encode_glb(&glb),
        Some(c) => {
            let lin: Vec<[f32; 3]> = c.iter().map(|&c| linear(c)).collect();
            geom::io::encode_glb_colored(&glb, &[Some(&lin)])
        }
    };
    bytes.with_context(|| format!("{}: cannot be shown", path.display()))
}

/// One row of a `--save-drapes` folder's samples.csv.
#[derive(Clone, Debug)]
struct SampleRow {
    index: u64,
    pose: String,
    e_dist_cm: f32,
}

/// The rows of `dir/samples.csv`.
fn read_samples(dir: &Path) -> anyhow::Result<Vec<SampleRow>> {
    let path = dir.join("samples.csv");
    let text = std::fs::read_to_string(&path).with_context(|| {
        format!(
            "{}: not a folder of garnet eval --save-drapes (reading {})",
            dir.display(),
            path.display()
        )
    })?;
    let mut rows = Vec::new();
    for (n, line) in text.lines().enumerate().skip(1) {
        if line.trim().is_empty() {
            continue;
        }
        let bad = || {
            format!(
                "{} line {}: expected index,pose,e_dist_cm,e_norm_deg,dqs_e_dist_cm",
                path.display(),
                n + 1
            )
        };
        // The pose may hold commas (quoted): the index is the first field, the numbers the
        // last three.
        let (index, rest) = line.split_once(',').with_context(bad)?;
        let mut tail = rest.rsplitn(4, ',');
        let (_dqs, _norm, dist, pose) = (tail.next(), tail.next(), tail.next(), tail.next());
        let (Some(dist), Some(pose)) = (dist, pose) else {
            bail!(bad());
        };
        rows.push(SampleRow {
            index: index.trim().parse().with_context(bad)?,
            pose: pose.trim_matches('"').replace("\"\"", "\""),
            e_dist_cm: dist.trim().parse().with_context(bad)?,
        });
    }
    if rows.is_empty() {
        bail!("{}: no samples", path.display());
    }
    Ok(rows)
}

/// The `k` rows with the largest E_dist, largest first.
fn worst(rows: &[SampleRow], k: usize) -> Vec<SampleRow> {
    let mut sorted = rows.to_vec();
    sorted.sort_by(|a, b| b.e_dist_cm.total_cmp(&a.e_dist_cm));
    sorted.truncate(k);
    sorted
}

fn describe_indices(rows: &[SampleRow]) -> String {
    let first: Vec<String> = rows.iter().take(5).map(|r| r.index.to_string()).collect();
    let more = if rows.len() > 5 { ", …" } else { "" };
    format!("{} samples: {}{more}", rows.len(), first.join(", "))
}

/// One saved drape of a `--save-drapes` folder and its per-vertex distances (cm).
struct HeatDrape {
    dir: PathBuf,
    index: u64,
    net: TriMesh,
    sim: TriMesh,
    dqs: Option<TriMesh>,
    body: Option<TriMesh>,
    dist_cm: Vec<f32>,
}

impl HeatDrape {
    /// Reads sample `index` of `dir`: the network's and the simulator's drapes (needed), the
    /// warped template and the body (shown when present).
    fn read(dir: &Path, index: u64) -> anyhow::Result<Self> {
        let part = |what: &str| dir.join(format!("{index:06}-{what}.ply"));
        let need = |what: &str| -> anyhow::Result<TriMesh> {
            let p = part(what);
            if !p.exists() {
                bail!(
                    "{}: no such file (sample {index} of {})",
                    p.display(),
                    dir.display()
                );
            }
            geom::io::read_mesh(&p).with_context(|| format!("{}: not a readable mesh", p.display()))
        };
        let net = need("net")?;
        let sim = need("sim")?;
        let optional = |what: &str| part(what).exists().then(|| need(what)).transpose();
        let (dqs, body) = (optional("dqs")?, optional("body")?);
        let dist_cm = geom::metrics::vertex_distances(&sim.vertices, &net.vertices)
            .with_context(|| {
                format!(
                    "{}: the network's and the simulator's drapes of sample {index} differ in \
                     vertex count",
                    dir.display()
                )
            })?
            .iter()
            .map(|d| d * 100.0)
            .collect();
        Ok(HeatDrape {
            dir: dir.to_path_buf(),
            index,
            net,
            sim,
            dqs,
            body,
            dist_cm,
        })
    }

    /// The page's meshes: the body, the network's drape as a heat map up to `high_cm`, the
    /// simulator's drape and the warped template (hidden).
    fn page_meshes(&self, high_cm: f32) -> anyhow::Result<Vec<PageMesh>> {
        let model = file_name(&self.dir);
        let at = |what: &str| self.dir.join(format!("{:06}-{what}.ply", self.index));
        let mut out = Vec::new();
        if let Some(body) = &self.body {
            out.push(PageMesh {
                name: format!("{model} body"),
                glb: encode(&at("body"), body, "body", palette::SKIN, None)?,
                visible: true,
            });
        }
        let colors = palette::heat_colors(&self.dist_cm, 0.0, high_cm);
        out.push(PageMesh {
            name: format!("{model} network (distance to simulator)"),
            glb: encode(&at("net"), &self.net, "network", [255; 3], Some(&colors))?,
            visible: true,
        });
        out.push(PageMesh {
            name: format!("{model} simulator"),
            glb: encode(
                &at("sim"),
                &self.sim,
                "simulator",
                palette::TSHIRT_BLUE,
                None,
            )?,
            visible: false,
        });
        if let Some(dqs) = &self.dqs {
            out.push(PageMesh {
                name: format!("{model} warped template (DQS)"),
                glb: encode(&at("dqs"), dqs, "dqs", palette::OLIVE, None)?,
                visible: false,
            });
        }
        Ok(out)
    }
}

/// The top of a colour scale showing `drapes`: their largest distance, rounded up to a
/// tenth of a centimetre (at least 0.1 cm).
fn scale_top<'a>(drapes: impl IntoIterator<Item = &'a HeatDrape>) -> f32 {
    let max = drapes
        .into_iter()
        .flat_map(|d| d.dist_cm.iter().copied())
        .filter(|d| d.is_finite())
        .fold(0.0f32, f32::max);
    ((max * 10.0 - 1e-3).ceil() / 10.0).max(0.1)
}

fn distance_legend(high_cm: f32) -> Legend {
    Legend {
        title: "network's distance to the simulator's drape, per vertex".into(),
        low: 0.0,
        high: high_cm,
        unit: "cm".into(),
    }
}

/// How many of each model's worst drapes `garnet eval --html` shows in 3D.
const WORST_SHOWN: usize = 3;

/// Writes `out/results.html` for `garnet eval --html`: results.md's tables, the two precision
/// charts (from `out`), and, when drapes were saved (`saved`: one folder per model), each
/// model's worst drapes as heat maps on one shared scale.
pub fn write_eval_page(out: &Path, saved: Option<&[PathBuf]>) -> anyhow::Result<PathBuf> {
    let md_path = out.join("results.md");
    let md = std::fs::read_to_string(&md_path)
        .with_context(|| format!("reading {}", md_path.display()))?;
    let mut before = markdown_html(md.trim_start_matches(|c| c != '\n').trim_start());
    before += "<h3>Precision curves</h3>\n<p>";
    for (png, alt) in [
        ("precision_dist.png", "vertex distance precision"),
        ("precision_norm.png", "face normal precision"),
    ] {
        let p = out.join(png);
        let bytes = std::fs::read(&p).with_context(|| format!("reading {}", p.display()))?;
        before += &format!(
            "<img class=\"chart\" alt=\"{alt}\" src=\"{}\">",
            data_url("image/png", &bytes)
        );
    }
    before += "</p>\n";
    let mut drapes = Vec::new();
    for dir in saved.unwrap_or_default() {
        for row in worst(&read_samples(dir)?, WORST_SHOWN) {
            drapes.push((HeatDrape::read(dir, row.index)?, row));
        }
    }
    let mut scenes = Vec::new();
    if !drapes.is_empty() {
        let high = scale_top(drapes.iter().map(|(d, _)| d));
        for (drape, row) in &drapes {
            scenes.push(Scene {
                title: format!(
                    "{} sample {} (pose {}): E_dist {:.2} cm",
                    file_name(&drape.dir),
                    row.index,
                    row.pose,
                    row.e_dist_cm
                ),
                meshes: drape.page_meshes(high)?,
                legend: Some(distance_legend(high)),
            });
        }
    }
    let title = md
        .lines()
        .next()
        .map_or("GarNet evaluation", |l| l.trim_start_matches('#').trim())
        .to_string();
    let page = Page {
        title,
        before,
        view_heading: (!scenes.is_empty()).then(|| {
            format!(
                "Worst drapes in 3D ({WORST_SHOWN} per model, by E_dist; the network's drape \
                 coloured by each vertex's distance to the simulator's)"
            )
        }),
        after: String::new(),
        scenes,
    };
    let path = out.join("results.html");
    write_page(&path, &page)?;
    Ok(path)
}
