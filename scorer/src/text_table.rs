//! A plain text table, written aligned for a terminal or as Markdown, and the number
//! formats of the report's cells (percentages, intervals, coverage).

use crate::report::ModelReport;

pub(crate) fn pct(v: Option<f64>) -> String {
    v.map_or("—".into(), |x| format!("{:.1}", 100.0 * x))
}

pub(crate) fn num(v: Option<f64>, digits: usize) -> String {
    v.map_or("—".into(), |x| format!("{x:.digits$}"))
}

/// A 95% interval of a rate, in %: "54.1–77.3".
pub(crate) fn pct_ci(v: Option<[f64; 2]>) -> String {
    v.map_or("—".into(), |[a, b]| {
        format!("{:.1}–{:.1}", 100.0 * a, 100.0 * b)
    })
}

/// A 95% interval of a mean: "0.12–0.30".
pub(crate) fn num_ci(v: Option<[f64; 2]>, digits: usize) -> String {
    v.map_or("—".into(), |[a, b]| format!("{a:.digits$}–{b:.digits$}"))
}

/// "answered/expected", marked when incomplete.
pub(crate) fn coverage_cell(m: &ModelReport) -> String {
    let c = &m.coverage;
    if c.complete {
        format!("{}/{}", c.answered, c.expected)
    } else {
        format!("{}/{} INCOMPLETE", c.answered, c.expected)
    }
}

/// A simple table rendered either aligned (terminal) or as Markdown.
pub(crate) struct Table {
    pub(crate) head: Vec<String>,
    pub(crate) rows: Vec<Vec<String>>,
}

impl Table {
    pub(crate) fn new(head: &[&str]) -> Self {
        Table {
            head: head.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    pub(crate) fn row(&mut self, r: Vec<String>) {
        self.rows.push(r);
    }

    pub(crate) fn text(&self) -> String {
        let n = self.head.len();
        let mut w = vec![0usize; n];
        for r in std::iter::once(&self.head).chain(&self.rows) {
            for (i, c) in r.iter().enumerate() {
                w[i] = w[i].max(c.chars().count());
            }
        }
        let mut out = String::new();
        let line = |r: &Vec<String>, out: &mut String| {
            for (i, c) in r.iter().enumerate() {
                let pad = w[i] - c.chars().count();
                if i == 0 {
                    out.push_str(c);
                    out.push_str(&" ".repeat(pad));
                } else {
                    out.push_str("  ");
                    out.push_str(&" ".repeat(pad));
                    out.push_str(c);
                }
            }
            out.push('\n');
        };
        line(&self.head, &mut out);
        let total: usize = w.iter().sum::<usize>() + 2 * (n - 1);
        out.push_str(&"-".repeat(total));
        out.push('\n');
        for r in &self.rows {
            line(r, &mut out);
        }
        out
    }

    pub(crate) fn markdown(&self) -> String {
        let mut out = String::new();
        let esc = |s: &str| s.replace('|', "\\|");
        out.push_str(&format!(
            "| {} |\n",
            self.head
                .iter()
                .map(|s| esc(s))
                .collect::<Vec<_>>()
                .join(" | ")
        ));
        out.push_str(&format!(
            "|{}|\n",
            self.head
                .iter()
                .enumerate()
                .map(|(i, _)| if i == 0 { " --- " } else { " ---: " })
                .collect::<Vec<_>>()
                .join("|")
        ));
        for r in &self.rows {
            out.push_str(&format!(
                "| {} |\n",
                r.iter().map(|s| esc(s)).collect::<Vec<_>>().join(" | ")
            ));
        }
        out
    }
}
