//! Answers as tables: the header and every row are written from one declaration of each
//! column (name, unit, how a row gives its cell), so a CSV header cannot drift from its rows.

use std::borrow::Cow;
use std::fmt::Write;

use super::fields::Reader;
use super::number::write_number;

#[derive(Clone, Debug, PartialEq)]
pub enum Cell {
    /// A quantity in the column's SI unit.
    Number(f64),
    /// A count or an index.
    Count(usize),
    /// Free text, such as a legend (quoted in CSV).
    Text(String),
    /// Nothing: a column that does not apply to this row.
    Empty,
}

enum Read<R> {
    Number(fn(&R) -> f64),
    Optional(fn(&R) -> Option<f64>),
    Count(fn(&R) -> usize),
    /// Text, written into the string given (a sweep's rows each have two: one buffer for
    /// all, not a string a cell).
    Text(fn(&R, &mut String)),
    /// A number read through a field's declaration ([`super::fields::columns`]).
    Field(Reader<R>),
}

pub struct Column<R> {
    pub name: Cow<'static, str>,
    /// SI unit of the column ("" for plain numbers, counts and text).
    pub unit: &'static str,
    read: Read<R>,
}

impl<R> Column<R> {
    const fn new(name: &'static str, unit: &'static str, read: Read<R>) -> Self {
        let name = Cow::Borrowed(name);
        Column { name, unit, read }
    }

    /// A column of quantities in `unit` (SI; "" for a plain number).
    pub const fn number(name: &'static str, unit: &'static str, read: fn(&R) -> f64) -> Self {
        Self::new(name, unit, Read::Number(read))
    }

    /// A column of quantities that some rows do not have (their cell is empty).
    pub const fn optional(
        name: &'static str,
        unit: &'static str,
        read: fn(&R) -> Option<f64>,
    ) -> Self {
        Self::new(name, unit, Read::Optional(read))
    }

    /// A column of counts or indices.
    pub const fn count(name: &'static str, read: fn(&R) -> usize) -> Self {
        Self::new(name, "", Read::Count(read))
    }

    /// A column of text, which `write` appends to the string it is given.
    pub const fn text(name: &'static str, write: fn(&R, &mut String)) -> Self {
        Self::new(name, "", Read::Text(write))
    }

    /// A column of numbers named `name`, in `unit`, that `read` gives (empty where `None`).
    pub fn read(name: String, unit: &'static str, read: Reader<R>) -> Self {
        let (name, read) = (Cow::Owned(name), Read::Field(read));
        Column { name, unit, read }
    }

    fn heading(&self) -> Heading {
        let (name, unit) = (self.name.to_string(), Cow::Borrowed(self.unit));
        Heading { name, unit }
    }

    /// The cell of `row` as a number, if it is one (a quantity present, or a count).
    pub fn value(&self, row: &R) -> Option<f64> {
        match self.cell(row) {
            Cell::Number(x) => Some(x),
            Cell::Count(n) => Some(n as f64),
            Cell::Text(_) | Cell::Empty => None,
        }
    }

    pub fn cell(&self, row: &R) -> Cell {
        match &self.read {
            Read::Number(read) => Cell::Number(read(row)),
            Read::Optional(read) => read(row).map_or(Cell::Empty, Cell::Number),
            Read::Count(read) => Cell::Count(read(row)),
            Read::Text(write) => {
                let mut text = String::new();
                write(row, &mut text);
                Cell::Text(text)
            }
            Read::Field(read) => read(row).map_or(Cell::Empty, Cell::Number),
        }
    }
}

/// The heading of a column of a built table.
#[derive(Clone, Debug, PartialEq)]
pub struct Heading {
    pub name: String,
    pub unit: Cow<'static, str>,
}

/// `name [unit]`, or `name` for a plain number (a CSV column's heading, an axis's label).
pub(super) fn with_unit(name: String, unit: &str) -> String {
    if unit.is_empty() {
        name
    } else {
        format!("{name} [{unit}]")
    }
}

/// A table of cells under headings, one row per record.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    pub headings: Vec<Heading>,
    pub rows: Vec<Vec<Cell>>,
}

impl Table {
    pub fn new<'a, R: 'a>(columns: &[Column<R>], rows: impl IntoIterator<Item = &'a R>) -> Table {
        Table {
            headings: columns.iter().map(Column::heading).collect(),
            rows: rows
                .into_iter()
                .map(|row| columns.iter().map(|c| c.cell(row)).collect())
                .collect(),
        }
    }

    /// Renames column `index`, in `unit` (a quantity the rows choose: a sweep's operating point).
    pub fn rename(&mut self, index: usize, name: &str, unit: &str) {
        if let Some(heading) = self.headings.get_mut(index) {
            heading.name = name.to_string();
            heading.unit = Cow::Owned(unit.to_string());
        }
    }

    /// The table with a column `name` in `unit` holding `value` on every row (a quantity the
    /// whole answer has, such as a fitted parameter beside each residual).
    pub fn with_constant(mut self, name: &str, unit: &'static str, value: Option<f64>) -> Table {
        let unit = Cow::Borrowed(unit);
        self.headings.push(Heading {
            name: name.to_string(),
            unit,
        });
        let cell = value.map_or(Cell::Empty, Cell::Number);
        for row in &mut self.rows {
            row.push(cell.clone());
        }
        self
    }

    /// CSV (RFC 4180): a header line (`radius [m]`), then a line a row, text quoted; `None`
    /// if a number is not finite (CSV has no place for it, as JSON has none).
    pub fn to_csv(&self) -> Option<String> {
        let labels = self
            .headings
            .iter()
            .map(|h| with_unit(h.name.clone(), &h.unit));
        let mut csv = Csv::new(labels, self.rows.len());
        for row in &self.rows {
            for (i, cell) in row.iter().enumerate() {
                csv.cell(i, cell);
            }
            csv.text.push('\n');
        }
        csv.finite.then_some(csv.text)
    }
}

/// [`Table::to_csv`] of `rows` under `columns`, straight from the rows: for many rows (a
/// sweep's) a table's cells, a vector a row and a string a text, cost more than the CSV.
pub fn csv<'a, R: 'a>(columns: &[Column<R>], rows: &'a [R]) -> Option<String> {
    let labels = columns
        .iter()
        .map(|c| with_unit(c.name.to_string(), c.unit));
    let mut csv = Csv::new(labels, rows.len());
    let mut text = String::new();
    for row in rows {
        for (i, column) in columns.iter().enumerate() {
            if let Read::Text(write) = column.read {
                text.clear();
                write(row, &mut text);
                csv.text(i, &text);
            } else {
                csv.cell(i, &column.cell(row));
            }
        }
        csv.text.push('\n');
    }
    csv.finite.then_some(csv.text)
}

/// CSV being written: one buffer, each number straight into it.
struct Csv {
    text: String,
    finite: bool,
    /// Each column's last number (its bits) and text: one equal to the one above (a sweep's
    /// outer axis, its answers at rest) is copied, as formatting is most of a sweep's CSV.
    above: Vec<(u64, String)>,
}

impl Csv {
    fn new(labels: impl Iterator<Item = String>, rows: usize) -> Csv {
        let labels: Vec<String> = labels.collect();
        let (mut text, columns) = (labels.join(",") + "\n", labels.len());
        // About 24 bytes a cell (a number of 17 digits and its exponent).
        text.reserve(24 * columns.max(1) * rows);
        Csv {
            text,
            finite: true,
            above: vec![(0, String::new()); columns],
        }
    }

    fn separate(&mut self, column: usize) {
        if column > 0 {
            self.text.push(',');
        }
    }

    fn cell(&mut self, column: usize, cell: &Cell) {
        match cell {
            Cell::Number(x) => self.number(column, *x),
            Cell::Count(n) => {
                self.separate(column);
                let _ = write!(self.text, "{n}");
            }
            Cell::Text(text) => self.text(column, text),
            Cell::Empty => self.separate(column),
        }
    }

    fn number(&mut self, column: usize, x: f64) {
        self.separate(column);
        self.finite &= x.is_finite();
        let Some((bits, above)) = self.above.get_mut(column) else {
            write_number(&mut self.text, x);
            return;
        };
        if *bits != x.to_bits() || above.is_empty() {
            let start = self.text.len();
            write_number(&mut self.text, x);
            above.clear();
            above.push_str(&self.text[start..]);
            *bits = x.to_bits();
        } else {
            self.text.push_str(above);
        }
    }

    /// `text`, quoted, as the cell of `column`.
    fn text(&mut self, column: usize, text: &str) {
        self.separate(column);
        self.text.push('"');
        if text.contains('"') {
            self.text.push_str(&text.replace('"', "\"\""));
        } else {
            self.text.push_str(text);
        }
        self.text.push('"');
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::format_number;

    /// A row's x and label.
    struct Row(f64, &'static str);

    const COLUMNS: [Column<Row>; 3] = [
        Column::count("index", |_| 7),
        Column::number("x", "m", |r| r.0),
        Column::text("label", |r, text| text.push_str(r.1)),
    ];

    #[test]
    fn the_header_and_the_rows_come_from_one_declaration() {
        let rows = [Row(2.5e-8, "a"), Row(0.5, "say \"b\"")];
        let mut table = Table::new(&COLUMNS, &rows);
        let expected = "index,x [m],label\n7,2.5e-8,\"a\"\n7,0.5,\"say \"\"b\"\"\"\n";
        assert_eq!(table.to_csv().as_deref(), Some(expected));
        // Written from the rows, the same text.
        assert_eq!(csv(&COLUMNS, &rows).as_deref(), Some(expected));
        // A number that is not finite has no CSV.
        let infinite = [Row(f64::INFINITY, "c")];
        assert_eq!(csv(&COLUMNS, &infinite), None);
        table.rename(1, "load", "N");
        assert!(table
            .to_csv()
            .unwrap()
            .starts_with("index,load [N],label\n"));
        assert_eq!(table.headings[1].unit, "N");
    }

    /// A number equal to the one above it is copied from the line above; a different one, or
    /// the same number in another column, is written afresh.
    #[test]
    fn a_number_repeated_down_a_column_is_written_as_it_was() {
        let xs = [0.1, 0.1, -0.0, 0.0, 0.0, 1e-9, 0.1, 0.1];
        let rows: Vec<Row> = xs.iter().map(|&x| Row(x, "l")).collect();
        let lines = xs
            .iter()
            .map(|x| format!("7,{},\"l\"\n", format_number(*x)));
        let expected = "index,x [m],label\n".to_string() + &lines.collect::<String>();
        assert_eq!(csv(&COLUMNS, &rows).as_deref(), Some(expected.as_str()));
        assert!(expected.contains("7,-0,\"l\"\n7,0,"));
        let twice = [
            Column::number("a", "", |r: &Row| r.0),
            Column::number("b", "", |r| r.0 / 3.0),
        ];
        assert_eq!(
            csv(&twice, &rows[..2]).as_deref(),
            Some("a,b\n0.1,0.03333333333333333\n0.1,0.03333333333333333\n")
        );
    }
}
