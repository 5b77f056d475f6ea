//! Self-contained HTML pages that show meshes in 3D in a browser (`garnet view`, `garnet eval
//! --html`): three.js, its orbit controls and glTF loader are embedded in the binary (vendored
//! from npm into `web/vendor/` at the repository root, minified) and inlined into every page as `data:`
//! URLs of an import map, and the meshes as base64 GLB. A page fetches nothing: it opens from
//! disk, offline.
//!
//! - [`Page`]: a title, HTML sections (tables, pictures) and [`Scene`]s, each some GLB meshes
//!   ([`PageMesh`]) and an optional heat-map [`Legend`]; [`Page::html`] writes the document.
//!   Several scenes share one 3D view and a menu to switch between them.
//! - Animated GLBs (morph-target animation) play with `THREE.AnimationMixer`, with play/pause
//!   and a frame slider; vertex colours (`COLOR_0`) show as they are.
//! - [`markdown_html`]: the Markdown subset of garnet's reports (headings, paragraphs, pipe
//!   tables) as HTML; [`base64`] and [`data_url`] to inline files.

mod markdown;

pub use markdown::markdown_html;

use serde_json::json;

use crate::palette;

/// The three.js release the pages embed.
pub const THREE_VERSION: &str = include_str!("../../../../web/vendor/three/VERSION");
const THREE_LICENSE: &str = include_str!("../../../../web/vendor/three/LICENSE");

/// The import map's modules: bare name and minified source.
const MODULES: [(&str, &str); 6] = [
    (
        "three/core",
        include_str!("../../../../web/vendor/three/build/three.core.min.js"),
    ),
    (
        "three",
        include_str!("../../../../web/vendor/three/build/three.module.min.js"),
    ),
    (
        "three/addons/controls/OrbitControls.js",
        include_str!("../../../../web/vendor/three/examples/jsm/controls/OrbitControls.js"),
    ),
    (
        "three/addons/loaders/GLTFLoader.js",
        include_str!("../../../../web/vendor/three/examples/jsm/loaders/GLTFLoader.js"),
    ),
    (
        "three/addons/utils/BufferGeometryUtils.js",
        include_str!("../../../../web/vendor/three/examples/jsm/utils/BufferGeometryUtils.js"),
    ),
    (
        "three/addons/utils/SkeletonUtils.js",
        include_str!("../../../../web/vendor/three/examples/jsm/utils/SkeletonUtils.js"),
    ),
];

const VIEWER_JS: &str = include_str!("viewer.js");
const PROBE_JS: &str = include_str!("probe.js");
const PAGE_CSS: &str = include_str!("page.css");

/// One mesh of a scene: a GLB file's bytes (any number of meshes, optionally animated).
#[derive(Clone, Debug)]
pub struct PageMesh {
    /// Shown beside its visibility checkbox.
    pub name: String,
    /// The GLB bytes.
    pub glb: Vec<u8>,
    /// Shown when the page opens (the checkbox can change it).
    pub visible: bool,
}

/// The colour scale of a heat map (the colours of [`palette::heat`]), shown under the view.
#[derive(Clone, Debug)]
pub struct Legend {
    /// What the colours measure, e.g. "distance to the simulator's drape".
    pub title: String,
    /// Value of the scale's low end (deep blue).
    pub low: f32,
    /// Value of the scale's high end (dark red); values above are drawn as it.
    pub high: f32,
    /// Unit of the values, e.g. "cm".
    pub unit: String,
}

/// Meshes shown together.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Name in the scene menu and above the view.
    pub title: String,
    /// The meshes.
    pub meshes: Vec<PageMesh>,
    /// The heat-map scale, when a mesh is coloured by one.
    pub legend: Option<Legend>,
}

/// A self-contained HTML page.
#[derive(Clone, Debug, Default)]
pub struct Page {
    /// Document title and heading.
    pub title: String,
    /// HTML put before the 3D view (trusted: written by the caller, e.g. [`markdown_html`]).
    pub before: String,
    /// Heading of the 3D view's section, when the page has other sections.
    pub view_heading: Option<String>,
    /// HTML put after the 3D view.
    pub after: String,
    /// The scenes of the 3D view (none: no view).
    pub scenes: Vec<Scene>,
}

/// `text` with `&`, `<`, `>` and `"` escaped for HTML text and attribute values.
pub fn escape_html(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            c => out.push(c),
        }
    }
    out
}

/// Standard base64 (RFC 4648, padded) of `bytes`.
pub fn base64(bytes: &[u8]) -> String {
    const ABC: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ABC[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// A `data:` URL of `bytes` with the media type `mime` (base64).
pub fn data_url(mime: &str, bytes: &[u8]) -> String {
    format!("data:{mime};base64,{}", base64(bytes))
}

/// `#rrggbb` of an sRGB colour.
fn hex([r, g, b]: [u8; 3]) -> String {
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// JSON to put inside a `<script>` element: `</` written `<\/` so no string ends the element.
fn script_json(value: &serde_json::Value) -> String {
    value.to_string().replace("</", "<\\/")
}

impl Page {
    /// The page as one HTML document: the modules' import map, the style, the sections, the
    /// scenes' data (base64 GLB) and the viewer script.
    pub fn html(&self) -> String {
        let title = escape_html(&self.title);
        let imports: serde_json::Map<String, serde_json::Value> = MODULES
            .iter()
            .map(|(name, code)| {
                (
                    (*name).to_string(),
                    json!(data_url("text/javascript", code.as_bytes())),
                )
            })
            .collect();
        let stops: Vec<String> = (0..=16)
            .map(|i| hex(palette::heat(i as f32 / 16.0)))
            .collect();
        let scenes: Vec<serde_json::Value> = self
            .scenes
            .iter()
            .map(|s| {
                json!({
                    "title": s.title,
                    "meshes": s.meshes.iter().map(|m| json!({
                        "name": m.name, "visible": m.visible, "glb": base64(&m.glb),
                    })).collect::<Vec<_>>(),
                    "legend": s.legend.as_ref().map(|l| json!({
                        "title": l.title, "low": l.low, "high": l.high, "unit": l.unit,
                    })),
                })
            })
            .collect();
        let data = json!({"scenes": scenes, "heat": stops});
        let licence = THREE_LICENSE.replace("--", "- -");
        let mut html = format!(
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
             <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
             <title>{title}</title>\n\
             <!-- Written by garnet. Embeds three.js {version} (build/three.core.min.js, \
             build/three.module.min.js, examples/jsm/controls/OrbitControls.js, \
             examples/jsm/loaders/GLTFLoader.js, examples/jsm/utils/BufferGeometryUtils.js, \
             examples/jsm/utils/SkeletonUtils.js; minified), under its licence:\n\n{licence}\n-->\n\
             <style>\n{PAGE_CSS}</style>\n<script>\n{PROBE_JS}</script>\n",
            version = THREE_VERSION.trim(),
        );
        let only_view = self.before.is_empty() && self.after.is_empty();
        html += "</head>\n";
        html += if only_view {
            "<body class=\"only-view\">\n"
        } else {
            "<body>\n"
        };
        html += &format!("<header><h1>{title}</h1></header>\n<main>\n");
        html += &self.before;
        if !self.scenes.is_empty() {
            if let Some(h) = &self.view_heading {
                html += &format!("<h3>{}</h3>\n", escape_html(h));
            }
            html += VIEW_HTML;
            html += &format!(
                "<script type=\"importmap\">{}</script>\n\
                 <script type=\"application/json\" id=\"garnet-data\">{}</script>\n\
                 <script type=\"module\">\n{VIEWER_JS}</script>\n",
                script_json(&json!({ "imports": imports })),
                script_json(&data),
            );
        } else {
            html += "<script>window.garnetPage.ready = true; \
                     document.documentElement.dataset.garnet = 'ready';</script>\n";
        }
        html += &self.after;
        html += "</main>\n</body>\n</html>\n";
        html
    }
}

/// The 3D view's controls, canvas holder and legend.
const VIEW_HTML: &str = r#"<section class="viewer">
<div class="bar">
<select id="garnet-scene" title="scene"></select>
<button id="garnet-play" type="button" title="play or pause the animation">pause</button>
<input id="garnet-frame" type="range" min="0" max="0" value="0" step="1" title="frame">
<span id="garnet-frame-label"></span>
<span id="garnet-meshes"></span>
</div>
<div id="garnet-view"><p id="garnet-status">loading…</p></div>
<div id="garnet-legend"></div>
</section>
"#;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc_4648() {
        for (raw, enc) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(raw.as_bytes()), enc);
        }
        assert_eq!(base64(&[0xff, 0xfe]), "//4=");
    }

    #[test]
    fn a_page_inlines_everything_and_fetches_nothing() {
        let page = Page {
            title: "a <test>".into(),
            scenes: vec![Scene {
                title: "s</script>".into(),
                meshes: vec![PageMesh {
                    name: "m".into(),
                    glb: vec![1, 2, 3],
                    visible: true,
                }],
                legend: Some(Legend {
                    title: "distance".into(),
                    low: 0.0,
                    high: 2.0,
                    unit: "cm".into(),
                }),
            }],
            ..Page::default()
        };
        let html = page.html();
        assert!(html.contains("<title>a &lt;test&gt;</title>"));
        assert!(!html.contains("http://") && !html.contains("https://"));
        assert_eq!(html.matches("</script>").count(), 4);
        assert!(html.contains("\"three\":\"data:text/javascript;base64,"));
        assert!(html.contains(&base64(&[1, 2, 3])));
        assert!(!html.contains(" src="));
    }

    #[test]
    fn vendored_modules_import_only_the_import_map_names() {
        let names: Vec<&str> = MODULES.iter().map(|m| m.0).collect();
        for (name, code) in MODULES {
            assert!(!code.contains("import(")); // no dynamic imports
            for part in code.split("from\"").skip(1) {
                let spec = &part[..part.find('"').unwrap()];
                assert!(names.contains(&spec), "{name} imports {spec}");
            }
        }
    }
}
