//! The Markdown of garnet's reports as HTML: `#` headings, paragraphs, pipe tables (numbers
//! right-aligned), `code` spans; everything else is text, escaped.

use super::escape_html;

/// Inline text: `code` spans as `<code>`, the rest escaped.
fn inline(text: &str) -> String {
    let mut out = String::new();
    for (i, part) in text.split('`').enumerate() {
        if i % 2 == 1 {
            out += &format!("<code>{}</code>", escape_html(part));
        } else {
            out += &escape_html(part);
        }
    }
    out
}

/// The cells of a table row `| a | b |`.
fn cells(line: &str) -> Vec<&str> {
    let t = line.trim();
    let t = t.strip_prefix('|').unwrap_or(t);
    let t = t.strip_suffix('|').unwrap_or(t);
    t.split('|').map(str::trim).collect()
}

/// Whether a cell reads as a number (right-aligned): digits with an optional sign, point,
/// percent sign or trailing `x`.
fn numeric(cell: &str) -> bool {
    let t = cell.trim_end_matches(['%', 'x']);
    !t.is_empty() && t.parse::<f64>().is_ok()
}

/// `md` (the subset above) as HTML.
pub fn markdown_html(md: &str) -> String {
    let mut html = String::new();
    let mut para: Vec<&str> = Vec::new();
    let lines: Vec<&str> = md.lines().collect();
    let flush = |para: &mut Vec<&str>, html: &mut String| {
        if !para.is_empty() {
            *html += &format!("<p>{}</p>\n", inline(&para.join(" ")));
            para.clear();
        }
    };
    let mut i = 0;
    while i < lines.len() {
        let line = lines[i].trim_end();
        if line.trim().is_empty() {
            flush(&mut para, &mut html);
        } else if let Some(rest) = line.strip_prefix('#') {
            flush(&mut para, &mut html);
            let level = 1 + rest.chars().take_while(|&c| c == '#').count();
            let text = rest.trim_start_matches('#').trim();
            // The page's own title is the h1: report headings start at h2.
            let h = (level + 1).min(6);
            html += &format!("<h{h}>{}</h{h}>\n", inline(text));
        } else if line.trim_start().starts_with('|') {
            flush(&mut para, &mut html);
            let header = cells(line);
            let mut j = i + 1;
            if j < lines.len() && cells(lines[j]).iter().all(|c| c.contains('-')) {
                j += 1;
            }
            html += "<table>\n<thead><tr>";
            for c in &header {
                html += &format!("<th>{}</th>", inline(c));
            }
            html += "</tr></thead>\n<tbody>\n";
            while j < lines.len() && lines[j].trim_start().starts_with('|') {
                html += "<tr>";
                for c in cells(lines[j]) {
                    if numeric(c) {
                        html += &format!("<td class=\"num\">{}</td>", inline(c));
                    } else {
                        html += &format!("<td>{}</td>", inline(c));
                    }
                }
                html += "</tr>\n";
                j += 1;
            }
            html += "</tbody>\n</table>\n";
            i = j;
            continue;
        } else {
            para.push(line.trim());
        }
        i += 1;
    }
    flush(&mut para, &mut html);
    html
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headings_tables_and_paragraphs() {
        let md = "# Title\n\nSome `a<b` text\non two lines.\n\n## T\n\n| g | e (cm) |\n|---|---:|\n| tshirt | 1.25 |\n| x | 3% |\n\nEnd.\n";
        let html = markdown_html(md);
        assert!(html.contains("<h2>Title</h2>"));
        assert!(html.contains("<p>Some <code>a&lt;b</code> text on two lines.</p>"));
        assert!(html.contains("<h3>T</h3>"));
        assert!(html.contains("<th>e (cm)</th>"));
        assert!(html.contains("<td>tshirt</td><td class=\"num\">1.25</td>"));
        assert!(html.contains("<td class=\"num\">3%</td>"));
        assert!(html.ends_with("<p>End.</p>\n"));
        assert_eq!(html.matches("<tr>").count(), 3);
    }
}
