//! The one Markdown table writer of the host tools, and the error cells every accuracy table
//! shares.

use std::fmt::Write as _;

/// How a column's cells line up: the separator row's `---` (left, Markdown's default) or
/// `---:` (right, for numbers).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Align {
    /// `---`.
    #[default]
    Left,
    /// `---:`.
    Right,
}

/// A column of a [`Table`]: its name and alignment. A `&str` or `String` is a left-aligned
/// column; [`Column::right`] makes a numeric one.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Column {
    name: String,
    align: Align,
}

impl Column {
    /// A right-aligned column (numbers).
    pub fn right(name: impl Into<String>) -> Self {
        Column {
            name: name.into(),
            align: Align::Right,
        }
    }
}

impl From<&str> for Column {
    fn from(name: &str) -> Self {
        Column {
            name: name.into(),
            align: Align::Left,
        }
    }
}

impl From<String> for Column {
    fn from(name: String) -> Self {
        Column {
            name,
            align: Align::Left,
        }
    }
}

/// A Markdown table: a header row and rows of cells, rendered with `|` separators. Every
/// table the host tools print is one of these; a `|` inside a cell is escaped.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Table {
    header: Vec<Column>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// A table with these columns (names, or [`Column`]s for alignment).
    pub fn new<C: Into<Column>>(header: impl IntoIterator<Item = C>) -> Self {
        Table {
            header: header.into_iter().map(Into::into).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends a row (missing cells render empty, extra ones are kept).
    pub fn row<S: Into<String>>(&mut self, cells: impl IntoIterator<Item = S>) -> &mut Self {
        self.rows.push(cells.into_iter().map(Into::into).collect());
        self
    }

    /// Rows so far.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// True without rows.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The table as Markdown, ending in a newline.
    pub fn render(&self) -> String {
        let mut s = String::new();
        let line = |s: &mut String, cells: &[&str], n: usize| {
            s.push('|');
            for k in 0..n {
                let c = cells.get(k).copied().unwrap_or("");
                let _ = write!(s, " {} |", c.replace('|', "\\|"));
            }
            s.push('\n');
        };
        let n = self
            .rows
            .iter()
            .map(Vec::len)
            .chain([self.header.len()])
            .max()
            .unwrap_or(0);
        let names: Vec<&str> = self.header.iter().map(|c| c.name.as_str()).collect();
        line(&mut s, &names, n);
        s.push('|');
        for k in 0..n {
            let align = self.header.get(k).map(|c| c.align).unwrap_or_default();
            s.push_str(match align {
                Align::Left => "---|",
                Align::Right => "---:|",
            });
        }
        s.push('\n');
        for r in &self.rows {
            let cells: Vec<&str> = r.iter().map(String::as_str).collect();
            line(&mut s, &cells, n);
        }
        s
    }
}

/// Root mean square, mean and count of errors.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ErrorStats {
    /// Root mean square.
    pub rmse: f64,
    /// Mean (signed).
    pub bias: f64,
    /// Half-width of the 95 % interval of the mean (1.96·sd/√n; 0 for fewer than 2).
    pub bias_ci95: f64,
    /// Errors.
    pub n: usize,
}

impl ErrorStats {
    /// Of `e`.
    pub fn of(e: &[f64]) -> Self {
        let n = e.len();
        if n == 0 {
            return ErrorStats::default();
        }
        let nf = n as f64;
        let bias = e.iter().sum::<f64>() / nf;
        let rmse = (e.iter().map(|x| x * x).sum::<f64>() / nf).sqrt();
        let bias_ci95 = if n > 1 {
            let var = e.iter().map(|x| (x - bias).powi(2)).sum::<f64>() / (nf - 1.0);
            1.96 * (var / nf).sqrt()
        } else {
            0.0
        };
        ErrorStats {
            rmse,
            bias,
            bias_ci95,
            n,
        }
    }
}

/// `RMSE / bias cm (n)` of errors in m, or `–` without any.
pub fn cm_cell(e: &[f64]) -> String {
    if e.is_empty() {
        return "–".into();
    }
    let s = ErrorStats::of(e);
    format!("{:.1} / {:+.1} ({})", s.rmse * 100.0, s.bias * 100.0, s.n)
}

/// `median / p95{unit} (median / p95)` of `ours` and, beside them in brackets, `theirs`
/// (quantiles at the rounded index, [`crate::eval::stats::quantile_at_rounded_index`]).
pub fn median_p95_beside(ours: &[f64], theirs: &[f64], unit: &str) -> String {
    let q = crate::eval::stats::quantile_at_rounded_index;
    format!(
        "{:.2} / {:.2}{unit} ({:.2} / {:.2})",
        q(ours, 0.5),
        q(ours, 0.95),
        q(theirs, 0.5),
        q(theirs, 0.95)
    )
}

/// `RMSE / bias ± 95 % cm (n)` of errors in m, or `–` without any.
pub fn cm_ci_cell(e: &[f64]) -> String {
    if e.is_empty() {
        return "–".into();
    }
    let s = ErrorStats::of(e);
    format!(
        "{:.1} / {:+.1} ± {:.1} ({})",
        s.rmse * 100.0,
        s.bias * 100.0,
        s.bias_ci95 * 100.0,
        s.n
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_renders_with_its_separator_and_escapes_bars() {
        let mut t = Table::new(["a", "b"]);
        t.row(["1", "x|y"]);
        assert_eq!(t.render(), "| a | b |\n|---|---|\n| 1 | x\\|y |\n");
    }

    #[test]
    fn right_columns_get_the_numeric_separator_and_short_rows_pad() {
        let mut t = Table::new([Column::from("name"), Column::right("n")]);
        t.row(["a"]);
        assert_eq!(t.render(), "| name | n |\n|---|---:|\n| a |  |\n");
    }

    #[test]
    fn error_stats_of_known_values() {
        let s = ErrorStats::of(&[0.01, -0.01, 0.03]);
        assert!((s.bias - 0.01).abs() < 1e-12);
        assert!((s.rmse - (0.0011f64 / 3.0).sqrt()).abs() < 1e-12);
        assert_eq!(s.n, 3);
        assert_eq!(cm_cell(&[]), "–");
    }
}
