//! A plain text table, written aligned for a terminal, as Markdown or as CSV, and the
//! number formats of the report's cells (percentages, intervals).

pub fn pct(v: Option<f64>) -> String {
    v.map_or("—".into(), |x| format!("{:.1}", 100.0 * x))
}

pub fn num(v: Option<f64>, digits: usize) -> String {
    v.map_or("—".into(), |x| format!("{x:.digits$}"))
}

/// A 95% interval of a rate, in %: "54.1–77.3".
pub fn pct_ci(v: Option<[f64; 2]>) -> String {
    v.map_or("—".into(), |[a, b]| {
        format!("{:.1}–{:.1}", 100.0 * a, 100.0 * b)
    })
}

/// A 95% interval of a mean: "0.12–0.30".
pub fn num_ci(v: Option<[f64; 2]>, digits: usize) -> String {
    v.map_or("—".into(), |[a, b]| format!("{a:.digits$}–{b:.digits$}"))
}

/// How a column's cells sit in its width.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Align {
    Left,
    Right,
}

/// How [`Table::text`] lays a table out for a terminal.
#[derive(Debug, Clone, Copy)]
pub struct TextStyle {
    /// Put before every line.
    pub indent: &'static str,
    /// Between two columns.
    pub gap: &'static str,
    /// A line of `-` under the head.
    pub rule: bool,
}

impl TextStyle {
    /// The report's tables: no indent, two spaces between columns, a rule under the head.
    pub const REPORT: TextStyle = TextStyle {
        indent: "",
        gap: "  ",
        rule: true,
    };
}

/// A CSV field: quoted when it holds a comma, a quote or a newline.
pub fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// A simple table rendered aligned (terminal), as Markdown or as CSV: the one writer of
/// the scorer's text tables. By default the first column is left-aligned and the others
/// right-aligned, each as wide as its widest cell.
pub struct Table {
    head: Vec<String>,
    rows: Vec<Vec<String>>,
    align: Vec<Align>,
    min_width: Vec<usize>,
    /// Markdown's separator row without spaces (`|---|---:|`).
    compact_markdown: bool,
}

impl Table {
    pub fn new(head: &[&str]) -> Self {
        Table::from_head(head.iter().map(|s| s.to_string()).collect())
    }

    pub fn from_head(head: Vec<String>) -> Self {
        let n = head.len();
        let align = (0..n)
            .map(|i| if i == 0 { Align::Left } else { Align::Right })
            .collect();
        Table {
            head,
            rows: Vec::new(),
            align,
            min_width: vec![0; n],
            compact_markdown: false,
        }
    }

    /// Each column's alignment (one per column of the head).
    pub fn aligned(mut self, align: &[Align]) -> Self {
        assert_eq!(align.len(), self.head.len(), "one alignment per column");
        self.align = align.to_vec();
        self
    }

    /// Each column's least width in the terminal layout (one per column of the head).
    pub fn min_widths(mut self, widths: &[usize]) -> Self {
        assert_eq!(widths.len(), self.head.len(), "one width per column");
        self.min_width = widths.to_vec();
        self
    }

    /// Markdown's separator row without spaces (`|---|---:|`).
    pub fn compact_markdown(mut self) -> Self {
        self.compact_markdown = true;
        self
    }

    pub fn row(&mut self, r: Vec<String>) {
        self.rows.push(r);
    }

    /// The report's terminal layout ([`TextStyle::REPORT`]).
    pub fn text(&self) -> String {
        self.text_with(TextStyle::REPORT)
    }

    pub fn text_with(&self, style: TextStyle) -> String {
        let n = self.head.len();
        let mut w = self.min_width.clone();
        for r in std::iter::once(&self.head).chain(&self.rows) {
            for (i, c) in r.iter().enumerate() {
                w[i] = w[i].max(c.chars().count());
            }
        }
        let mut out = String::new();
        let line = |r: &Vec<String>, out: &mut String| {
            out.push_str(style.indent);
            for (i, c) in r.iter().enumerate() {
                let pad = " ".repeat(w[i] - c.chars().count());
                if i > 0 {
                    out.push_str(style.gap);
                }
                match self.align[i] {
                    Align::Left => {
                        out.push_str(c);
                        out.push_str(&pad);
                    }
                    Align::Right => {
                        out.push_str(&pad);
                        out.push_str(c);
                    }
                }
            }
            out.push('\n');
        };
        line(&self.head, &mut out);
        if style.rule {
            let total: usize = w.iter().sum::<usize>() + style.gap.len() * (n - 1);
            out.push_str(&"-".repeat(total));
            out.push('\n');
        }
        for r in &self.rows {
            line(r, &mut out);
        }
        out
    }

    pub fn markdown(&self) -> String {
        let mut out = String::new();
        let esc = |s: &str| s.replace('|', "\\|");
        let line = |r: &[String]| {
            format!(
                "| {} |\n",
                r.iter().map(|s| esc(s)).collect::<Vec<_>>().join(" | ")
            )
        };
        out.push_str(&line(&self.head));
        let rule: Vec<&str> = self
            .align
            .iter()
            .map(|a| match (a, self.compact_markdown) {
                (Align::Left, false) => " --- ",
                (Align::Right, false) => " ---: ",
                (Align::Left, true) => "---",
                (Align::Right, true) => "---:",
            })
            .collect();
        out.push_str(&format!("|{}|\n", rule.join("|")));
        for r in &self.rows {
            out.push_str(&line(r));
        }
        out
    }

    /// The head and the rows as CSV ([`csv_field`]).
    pub fn csv(&self) -> String {
        let mut out = String::new();
        for r in std::iter::once(&self.head).chain(&self.rows) {
            let fields: Vec<String> = r.iter().map(|c| csv_field(c)).collect();
            out.push_str(&fields.join(","));
            out.push('\n');
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Table {
        let mut t = Table::new(&["model", "n"]);
        t.row(vec!["a|b".into(), "12".into()]);
        t.row(vec!["x,\"y\"".into(), "3".into()]);
        t
    }

    #[test]
    fn text_markdown_and_csv() {
        let t = sample();
        assert_eq!(t.text(), "model   n\n---------\na|b    12\nx,\"y\"   3\n");
        assert_eq!(
            t.markdown(),
            "| model | n |\n| --- | ---: |\n| a\\|b | 12 |\n| x,\"y\" | 3 |\n"
        );
        assert_eq!(t.csv(), "model,n\na|b,12\n\"x,\"\"y\"\"\",3\n");
    }

    #[test]
    fn styles_widths_and_alignment() {
        let t = sample()
            .aligned(&[Align::Left, Align::Left])
            .min_widths(&[6, 3])
            .compact_markdown();
        let style = TextStyle {
            indent: "  ",
            gap: " ",
            rule: false,
        };
        assert_eq!(
            t.text_with(style),
            "  model  n  \n  a|b    12 \n  x,\"y\"  3  \n"
        );
        assert!(t.markdown().contains("\n|---|---|\n"), "{}", t.markdown());
    }
}
