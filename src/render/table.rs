//! Answers as tables: each output declares its columns once (name, unit, how a row gives its
//! cell), and the header and every row are written from that one declaration, so a CSV
//! header cannot drift from its rows.

use std::borrow::Cow;

use super::fields::Reader;
use super::number::format_number;

/// One cell of a table.
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

/// How a column reads its cell off a row.
enum Read<R> {
    Number(fn(&R) -> f64),
    Optional(fn(&R) -> Option<f64>),
    Count(fn(&R) -> usize),
    Text(fn(&R) -> String),
    /// A number read through a field's declaration ([`super::fields::columns`]).
    Field(Reader<R>),
}

/// A column of a table whose rows are `R`s.
pub struct Column<R> {
    pub name: Cow<'static, str>,
    /// SI unit of the column ("" for plain numbers, counts and text).
    pub unit: &'static str,
    read: Read<R>,
}

impl<R> Column<R> {
    /// A column of quantities in `unit` (SI; "" for a plain number).
    pub const fn number(name: &'static str, unit: &'static str, read: fn(&R) -> f64) -> Self {
        Column {
            name: Cow::Borrowed(name),
            unit,
            read: Read::Number(read),
        }
    }

    /// A column of quantities that some rows do not have (their cell is empty).
    pub const fn optional(
        name: &'static str,
        unit: &'static str,
        read: fn(&R) -> Option<f64>,
    ) -> Self {
        Column {
            name: Cow::Borrowed(name),
            unit,
            read: Read::Optional(read),
        }
    }

    /// A column of counts or indices.
    pub const fn count(name: &'static str, read: fn(&R) -> usize) -> Self {
        Column {
            name: Cow::Borrowed(name),
            unit: "",
            read: Read::Count(read),
        }
    }

    /// A column of text.
    pub const fn text(name: &'static str, read: fn(&R) -> String) -> Self {
        Column {
            name: Cow::Borrowed(name),
            unit: "",
            read: Read::Text(read),
        }
    }

    /// A column of numbers named `name`, in `unit`, that `read` gives (empty where `None`).
    pub fn read(name: String, unit: &'static str, read: Reader<R>) -> Self {
        Column {
            name: Cow::Owned(name),
            unit,
            read: Read::Field(read),
        }
    }

    /// The cell of `row` as a number, if it is one (a quantity present, or a count).
    pub fn value(&self, row: &R) -> Option<f64> {
        match self.cell(row) {
            Cell::Number(x) => Some(x),
            Cell::Count(n) => Some(n as f64),
            Cell::Text(_) | Cell::Empty => None,
        }
    }

    /// The cell of `row`.
    pub fn cell(&self, row: &R) -> Cell {
        match &self.read {
            Read::Number(read) => Cell::Number(read(row)),
            Read::Optional(read) => read(row).map_or(Cell::Empty, Cell::Number),
            Read::Count(read) => Cell::Count(read(row)),
            Read::Text(read) => Cell::Text(read(row)),
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

impl Heading {
    /// The column's name with its unit: `radius [m]`, or `friction_coefficient`.
    pub fn label(&self) -> String {
        if self.unit.is_empty() {
            self.name.clone()
        } else {
            format!("{} [{}]", self.name, self.unit)
        }
    }
}

/// A table of cells under headings, one row per record.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    pub headings: Vec<Heading>,
    pub rows: Vec<Vec<Cell>>,
}

impl Table {
    /// The table of `rows` under `columns`.
    pub fn new<'a, R: 'a>(columns: &[Column<R>], rows: impl IntoIterator<Item = &'a R>) -> Table {
        Table {
            headings: columns
                .iter()
                .map(|c| Heading {
                    name: c.name.to_string(),
                    unit: Cow::Borrowed(c.unit),
                })
                .collect(),
            rows: rows
                .into_iter()
                .map(|row| columns.iter().map(|c| c.cell(row)).collect())
                .collect(),
        }
    }

    /// Renames column `index` and gives it `unit` (a column whose quantity depends on the
    /// rows, such as the operating point a sweep varies).
    pub fn rename(&mut self, index: usize, name: &str, unit: &str) {
        if let Some(heading) = self.headings.get_mut(index) {
            heading.name = name.to_string();
            heading.unit = Cow::Owned(unit.to_string());
        }
    }

    /// CSV (RFC 4180): one header line, each column named with its unit (`radius [m]`),
    /// then one line per row; numbers in their shortest round-trip form, text quoted.
    pub fn to_csv(&self) -> String {
        let mut csv = String::new();
        let names: Vec<String> = self.headings.iter().map(Heading::label).collect();
        csv.push_str(&names.join(","));
        csv.push('\n');
        for row in &self.rows {
            let cells: Vec<String> = row.iter().map(csv_cell).collect();
            csv.push_str(&cells.join(","));
            csv.push('\n');
        }
        csv
    }
}

fn csv_cell(cell: &Cell) -> String {
    match cell {
        Cell::Number(x) => format_number(*x),
        Cell::Count(n) => n.to_string(),
        Cell::Text(text) => format!("\"{}\"", text.replace('"', "\"\"")),
        Cell::Empty => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Row {
        x: f64,
        label: &'static str,
    }

    const COLUMNS: [Column<Row>; 3] = [
        Column::count("index", |_| 7),
        Column::number("x", "m", |r| r.x),
        Column::text("label", |r| r.label.to_string()),
    ];

    #[test]
    fn the_header_and_the_rows_come_from_one_declaration() {
        let rows = [
            Row {
                x: 2.5e-8,
                label: "a",
            },
            Row {
                x: 0.5,
                label: "say \"b\"",
            },
        ];
        let mut table = Table::new(&COLUMNS, &rows);
        assert_eq!(
            table.to_csv(),
            "index,x [m],label\n7,2.5e-8,\"a\"\n7,0.5,\"say \"\"b\"\"\"\n"
        );
        table.rename(1, "load", "N");
        assert!(table.to_csv().starts_with("index,load [N],label\n"));
        assert_eq!(table.headings[1].unit, "N");
    }
}
