//! Every answer leaves through here, as JSON, CSV or SVG. The job layer defines the answers
//! ([`Output`]); the HTTP service and the command line choose a [`Format`] ([`negotiate`] for
//! HTTP) and render an [`Answer`] into bytes.

pub mod fields;
pub mod fixed;
pub(crate) mod json;
mod negotiate;
mod number;
pub mod svg;
mod table;

use std::any::{Any, TypeId};
use std::fmt;

use serde::de::DeserializeOwned;
use serde::{Serialize, Serializer};
use serde_json::value::RawValue;

pub use fields::{Field, Fields, UnitGroups};
pub use fixed::{Fixed, Text, UnitTable};
pub use negotiate::negotiate;
pub use number::format_number;
pub use table::{csv, Cell, Column, Heading, Table};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    Json,
    Csv,
    /// The answer's picture ([`svg`]).
    Svg,
}

impl Format {
    /// Every format, in the service's order of preference (the first when the client
    /// accepts any), which is also the variants' (the tables below are in it).
    pub const ALL: [Format; 3] = [Format::Json, Format::Csv, Format::Svg];

    /// The format named `name` (`json`, `csv`, `svg`), as a `?format=` query gives it.
    pub fn from_name(name: &str) -> Option<Format> {
        Format::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The format's short name, also the extension of a file of it.
    pub fn name(self) -> &'static str {
        ["json", "csv", "svg"][self as usize]
    }

    /// The media type a client names in `Accept`.
    pub fn media_type(self) -> &'static str {
        ["application/json", "text/csv", "image/svg+xml"][self as usize]
    }

    /// The `Content-Type` of an answer in this format.
    pub fn content_type(self) -> &'static str {
        match self {
            Format::Csv => "text/csv; charset=utf-8; header=present",
            _ => self.media_type(),
        }
    }

    /// `text` with the provenance `line` ([`crate::job::Meta::provenance`]) where the format
    /// still parses: CSV as a first `#` line (pandas' `comment="#"` skips it), SVG as an XML
    /// comment after any XML declaration, JSON not at all (its `meta` holds more).
    pub fn with_provenance(self, text: String, line: &str) -> String {
        match self {
            Format::Json => text,
            Format::Csv => format!("# {line}\n{text}"),
            Format::Svg => {
                // `--` may not appear in an XML comment.
                let mut safe = line.to_string();
                while safe.contains("--") {
                    safe = safe.replace("--", "- -");
                }
                let after_declaration = match text.find("?>") {
                    Some(end) if text.starts_with("<?xml") => end + 2,
                    _ => 0,
                };
                let (declaration, root) = text.split_at(after_declaration);
                let newline = if declaration.is_empty() { "" } else { "\n" };
                format!(
                    "{declaration}{newline}<!-- {safe} -->\n{}",
                    root.trim_start()
                )
            }
        }
    }

    /// The format a client prefers among `offered`, from the values of its `Accept`
    /// headers; `None` when it accepts none of them.
    pub fn negotiate<'a>(
        accept: impl IntoIterator<Item = &'a str>,
        offered: &[Format],
    ) -> Option<Format> {
        let types: Vec<&str> = offered.iter().map(|f| f.media_type()).collect();
        negotiate(accept, &types).map(|i| offered[i])
    }
}

/// Why an answer could not be rendered or drawn: a fault of the service, never of the job.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct RenderError(String);

impl RenderError {
    pub fn new(message: impl Into<String>) -> RenderError {
        RenderError(message.into())
    }

    fn non_finite() -> RenderError {
        RenderError("the result holds a non-finite number".to_string())
    }
}

/// The answer of a job kind: JSON through serde, and one table for CSV.
pub trait Output: Serialize + fmt::Debug + Send + Sync + 'static {
    /// The unit of every numeric field of the JSON answer (outside `meta.input`): a
    /// `static` ([`Fixed`]), so that its JSON is rendered once.
    const UNITS: &'static UnitTable;

    /// What the answer's picture is drawn from, read back from its JSON (so that an answer
    /// made in another process, or assembled from parts, is drawn the same).
    type Picture: Picture;

    /// The answer as one table, its columns declared once by the output.
    fn table(&self) -> Table;

    /// The table as CSV (`None` if a number in it is not finite). An output of many rows
    /// writes it from its rows ([`csv`]) rather than through [`Output::table`].
    fn csv(&self) -> Option<String> {
        self.table().to_csv()
    }

    /// What a person reading the answer should be told beside it, if anything (a sweep
    /// whose points the model refused in part): the command line says it on stderr.
    fn notice(&self) -> Option<String> {
        None
    }
}

/// The parts of an answer its picture shows: a typed view of the answer's JSON (the
/// output's own types), read back from the JSON.
pub trait Picture: DeserializeOwned {
    /// The picture.
    fn chart(self) -> Result<svg::Chart, RenderError>;
}

/// The picture of the answer whose JSON is `json`, drawn as `P`.
pub fn draw<P: Picture>(json: &[u8]) -> Result<svg::Chart, RenderError> {
    let picture: P =
        serde_json::from_slice(json).map_err(|e| RenderError::new(format!("the answer: {e}")))?;
    picture.chart()
}

/// What [`Answer`] needs of an output, object-safe.
trait Render: Any + fmt::Debug + Send + Sync {
    fn json(&self, pretty: bool) -> Result<Vec<u8>, RenderError>;
    fn table(&self) -> Table;
    fn csv(&self) -> Option<String>;
    fn notice(&self) -> Option<String>;
    fn into_any(self: Box<Self>) -> Box<dyn Any>;
}

impl<T: Output> Render for T {
    fn json(&self, pretty: bool) -> Result<Vec<u8>, RenderError> {
        json::write(self, pretty)
    }

    fn table(&self) -> Table {
        Output::table(self)
    }

    fn csv(&self) -> Option<String> {
        Output::csv(self)
    }

    fn notice(&self) -> Option<String> {
        Output::notice(self)
    }

    fn into_any(self: Box<Self>) -> Box<dyn Any> {
        self
    }
}

/// Draws an answer from its JSON (each job kind has its own).
pub type Draw = fn(&[u8]) -> Result<svg::Chart, RenderError>;

/// The answer to any job, whatever its kind, and how to draw it.
#[derive(Debug)]
pub struct Answer(Box<dyn Render>, Draw);

impl Answer {
    pub fn new<T: Output>(output: T) -> Answer {
        Answer(Box::new(output), draw::<T::Picture>)
    }

    /// The answer in `format`: compact JSON, CSV, or its picture.
    pub fn render(&self, format: Format) -> Result<Vec<u8>, RenderError> {
        match format {
            Format::Json => self.0.json(false),
            Format::Svg => draw_svg(self.1, &self.0.json(false)?).map(String::into_bytes),
            Format::Csv => self
                .0
                .csv()
                .map(String::into_bytes)
                .ok_or_else(RenderError::non_finite),
        }
    }

    /// Indented JSON, for people reading a terminal.
    pub fn to_pretty_json(&self) -> Result<String, RenderError> {
        let json = self.0.json(true)?;
        String::from_utf8(json).map_err(|e| RenderError(e.to_string()))
    }

    /// The answer's table (the rows of its CSV).
    pub fn table(&self) -> Table {
        self.0.table()
    }

    /// What to tell a person beside the answer ([`Output::notice`]).
    pub fn notice(&self) -> Option<String> {
        self.0.notice()
    }

    /// The output, if it is a `T`; else the answer back.
    pub fn downcast<T: Output>(self) -> Result<T, Answer> {
        if (*self.0).type_id() != TypeId::of::<T>() {
            return Err(self);
        }
        let any = self.0.into_any();
        Ok(*any.downcast().expect("the type was checked above"))
    }
}

/// Answers are equal when they write the same JSON; one that cannot be written (a number
/// not finite) equals none.
impl PartialEq for Answer {
    fn eq(&self, other: &Answer) -> bool {
        matches!((self.0.json(false), other.0.json(false)), (Ok(a), Ok(b)) if a == b)
    }
}

/// Writes the answer's JSON (for serde_json serializers: it goes in as raw JSON).
impl Serialize for Answer {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let json = self.0.json(false).map_err(serde::ser::Error::custom)?;
        let text = String::from_utf8(json).map_err(serde::ser::Error::custom)?;
        let raw = RawValue::from_string(text).map_err(serde::ser::Error::custom)?;
        raw.serialize(s)
    }
}

/// The picture `draw` makes of the answer whose JSON is `json`, as SVG.
pub fn draw_svg(draw: Draw, json: &[u8]) -> Result<String, RenderError> {
    draw(json)
        .map(|chart| chart.to_svg())
        .map_err(|e| RenderError(format!("cannot draw the answer: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::unit_table;

    #[test]
    fn provenance_goes_where_each_format_still_parses() {
        let line = "thirdbody 0.1.0 (commit a--b-), model 1.2.0";
        assert_eq!(Format::Json.with_provenance("{}".into(), line), "{}");
        assert_eq!(
            Format::Csv.with_provenance("x\n1\n".into(), line),
            "# thirdbody 0.1.0 (commit a--b-), model 1.2.0\nx\n1\n"
        );
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg"/>"#;
        let comment = "<!-- thirdbody 0.1.0 (commit a- -b-), model 1.2.0 -->";
        assert_eq!(
            Format::Svg.with_provenance(svg.into(), line),
            format!("{comment}\n{svg}")
        );
        let declared = format!("<?xml version=\"1.0\"?>\n{svg}");
        assert_eq!(
            Format::Svg.with_provenance(declared, line),
            format!("<?xml version=\"1.0\"?>\n{comment}\n{svg}")
        );
    }

    crate::described! {
        #[derive(Debug, PartialEq, Serialize)]
        struct Point {
            x: f64 => [number "m"],
        }
    }

    /// The picture of an output drawn nowhere in these tests.
    #[derive(serde::Deserialize)]
    struct Undrawn {}

    impl Picture for Undrawn {
        fn chart(self) -> Result<svg::Chart, RenderError> {
            Err(RenderError::new("not drawn in these tests"))
        }
    }

    impl Output for Point {
        const UNITS: &'static UnitTable = unit_table!(Point);
        type Picture = Undrawn;

        /// The columns its fields declare.
        fn table(&self) -> Table {
            Table::new(&fields::columns::<Point>(), [self])
        }
    }

    #[test]
    fn an_answer_renders_in_every_format_and_refuses_a_non_finite_number() {
        let answer = Answer::new(Point { x: 0.5 });
        assert_eq!(answer.render(Format::Json).unwrap(), br#"{"x":0.5}"#);
        assert_eq!(answer.render(Format::Csv).unwrap(), b"x [m]\n0.5\n");
        assert_eq!(answer, Answer::new(Point { x: 0.5 }));
        assert_eq!(serde_json::to_string(&answer).unwrap(), r#"{"x":0.5}"#);
        assert_eq!(answer.downcast::<Point>().unwrap(), Point { x: 0.5 });
        let bad = Answer::new(Point { x: f64::NAN });
        assert!(bad.render(Format::Json).is_err());
        assert!(bad.render(Format::Csv).is_err());
        assert!(bad.to_pretty_json().is_err());
    }

    crate::described! {
        /// An answer holding another.
        #[derive(Debug, PartialEq, Serialize)]
        struct Holder {
            inner: Answer => [],
            points: Vec<f64> => [list "m"],
        }
    }

    impl Output for Holder {
        const UNITS: &'static UnitTable = unit_table!(Holder);
        type Picture = Undrawn;

        fn table(&self) -> Table {
            const COLUMNS: [Column<f64>; 1] = [Column::number("x", "m", |x| *x)];
            Table::new(&COLUMNS, &self.points)
        }
    }

    #[test]
    fn an_answer_written_while_another_is_and_one_after_a_larger_one_render_whole() {
        let holder = Answer::new(Holder {
            inner: Answer::new(Point { x: 0.5 }),
            points: vec![0.25; 2],
        });
        let json = holder.render(Format::Json).unwrap();
        assert_eq!(json, br#"{"inner":{"x":0.5},"points":[0.25,0.25]}"#);
        let large = Answer::new(Holder {
            inner: Answer::new(Point { x: 1.0 }),
            points: vec![0.125; 20_000],
        });
        let json = large.render(Format::Json).unwrap();
        assert!(json.len() > 100_000);
        assert!(json.ends_with(b",0.125]}"));
        // Written into the large one's room, and not left holding it.
        let json = holder.render(Format::Json).unwrap();
        assert_eq!(json, br#"{"inner":{"x":0.5},"points":[0.25,0.25]}"#);
        assert!(json.capacity() <= json.len() + json.len() / 8 + 64);
    }
}
