//! The index page of a campaign: a thumbnail per variant, the results table (sortable by
//! any column), failed and out-of-tolerance variants marked.
//!
//! The page takes the table as `collect` writes it (a header and rows of cells) and the
//! state of each row, so it depends on no campaign type; the thumbnails are PNG bytes
//! (`render` of each variant's output, made by the caller).

use std::fmt::Write;

use crate::page::{escape, head, png_data_url, SORT_JS};

/// How a variant came out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowState {
    /// Made, seams within tolerance.
    Ok,
    /// Made, seams out of tolerance.
    OutOfTolerance,
    /// The morph or a writer failed.
    Failed,
    /// Not made yet.
    Pending,
}

impl RowState {
    /// The state of `collect`'s `state` column (`ok`, `out_of_tolerance`, `failed`,
    /// `pending`); `None` for another word.
    pub fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "ok" => Self::Ok,
            "out_of_tolerance" => Self::OutOfTolerance,
            "failed" => Self::Failed,
            "pending" => Self::Pending,
            _ => return None,
        })
    }

    fn class(self) -> &'static str {
        match self {
            Self::Ok => "",
            Self::OutOfTolerance => " class=\"bad\"",
            Self::Failed => " class=\"failed\"",
            Self::Pending => " class=\"pending\"",
        }
    }

    fn label(self) -> &'static str {
        match self {
            Self::Ok => "ok",
            Self::OutOfTolerance => "OUT OF TOLERANCE",
            Self::Failed => "FAILED",
            Self::Pending => "pending",
        }
    }
}

/// One variant of the page.
#[derive(Debug, Clone)]
pub struct Row {
    /// The variant id (first column).
    pub id: String,
    /// Its cells, one per column of [`CampaignPage::columns`] (the id included).
    pub cells: Vec<String>,
    /// Its state.
    pub state: RowState,
    /// A picture of its output (PNG), if it has one.
    pub thumbnail: Option<Vec<u8>>,
}

/// A campaign's index page.
#[derive(Debug, Clone)]
pub struct CampaignPage {
    /// The page title.
    pub title: String,
    /// Column names.
    pub columns: Vec<String>,
    /// The variants.
    pub rows: Vec<Row>,
}

/// The result columns of `collect` plotted against each parameter.
pub const PLOTTED: [&str; 4] = ["max_gap_closest", "max_g1_angle_deg", "control_points", "total_ms"];

impl CampaignPage {
    /// Scatter plots (SVG) of each parameter (the columns between the id and `state`)
    /// against each [`PLOTTED`] result, made variants only; out-of-tolerance and failed
    /// ones as red crosses. Empty when nothing is made.
    pub fn scatter_plots(&self) -> String {
        let Some(state) = self.columns.iter().position(|c| c == "state") else { return String::new() };
        let made: Vec<&Row> = self.rows.iter().filter(|r| r.state != RowState::Pending).collect();
        let mut out = String::new();
        for y_name in PLOTTED {
            let Some(yc) = self.columns.iter().position(|c| c == y_name) else { continue };
            for xc in 1..state {
                let pts: Vec<crate::plots::Point> = made
                    .iter()
                    .map(|r| crate::plots::Point {
                        x: r.cells.get(xc).and_then(|c| c.parse().ok()).unwrap_or(f64::NAN),
                        y: r.cells.get(yc).and_then(|c| c.parse().ok()).unwrap_or(f64::NAN),
                        marked: r.state != RowState::Ok,
                    })
                    .collect();
                if let Some(svg) = crate::plots::scatter_svg(&self.columns[xc], y_name, &pts, 360, 240) {
                    out.push_str(&svg);
                    out.push('\n');
                }
            }
        }
        if out.is_empty() {
            return out;
        }
        format!("<h2>Parameters against results</h2><div class=\"plots\">\n{out}</div>\n")
    }

    /// The page as HTML.
    pub fn to_html(&self) -> String {
        let mut h = head(&self.title);
        let count = |s: RowState| self.rows.iter().filter(|r| r.state == s).count();
        let _ = writeln!(
            h,
            "<h1>{}</h1><p>{} variants: {} ok, {} out of tolerance, {} failed, {} pending.</p>",
            escape(&self.title),
            self.rows.len(),
            count(RowState::Ok),
            count(RowState::OutOfTolerance),
            count(RowState::Failed),
            count(RowState::Pending)
        );
        h.push_str("<h2>Variants</h2><div class=\"thumbs\">\n");
        for r in &self.rows {
            let pic = match &r.thumbnail {
                Some(png) => format!("<img alt=\"{}\" src=\"{}\">", escape(&r.id), png_data_url(png)),
                None => "<div style=\"width:240px;height:120px;border:1px dashed #bbb\"></div>".into(),
            };
            let _ = writeln!(
                h,
                "<figure id=\"variant-{id}\"{}>{pic}<figcaption>{id}: {}</figcaption></figure>",
                r.state.class(),
                r.state.label(),
                id = escape(&r.id)
            );
        }
        h.push_str("</div>\n<h2>Results</h2><p>Click a column to sort.</p><table class=\"sortable\" id=\"results\"><thead><tr>");
        for c in &self.columns {
            let _ = write!(h, "<th>{}</th>", escape(c));
        }
        h.push_str("</tr></thead><tbody>\n");
        for r in &self.rows {
            let _ = write!(h, "<tr{} data-state=\"{}\">", r.state.class(), r.state.label());
            for c in &r.cells {
                let _ = write!(h, "<td data-v=\"{0}\">{0}</td>", escape(c));
            }
            h.push_str("</tr>\n");
        }
        h.push_str("</tbody></table>\n");
        h.push_str(&self.scatter_plots());
        let _ = write!(h, "<script>{SORT_JS}</script>\n</body></html>\n");
        h
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marks_and_counts() {
        let row = |id: &str, s| Row { id: id.into(), cells: vec![id.into(), "1.5".into()], state: s, thumbnail: None };
        let p = CampaignPage {
            title: "c <1>".into(),
            columns: vec!["id".into(), "x".into()],
            rows: vec![row("v0", RowState::Ok), row("v1", RowState::Failed), row("v2", RowState::OutOfTolerance)],
        };
        let h = p.to_html();
        assert!(h.contains("3 variants: 1 ok, 1 out of tolerance, 1 failed, 0 pending"));
        assert!(h.contains("<tr class=\"failed\" data-state=\"FAILED\">"));
        assert!(h.contains("<tr class=\"bad\" data-state=\"OUT OF TOLERANCE\">"));
        assert!(h.contains("c &lt;1&gt;"));
        assert_eq!(RowState::parse("out_of_tolerance"), Some(RowState::OutOfTolerance));
        assert_eq!(RowState::parse("x"), None);
    }
}
