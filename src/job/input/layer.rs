//! The Kelvin layer, as rolling and three-body inputs give it.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use serde_json::json;

use super::units::{is_bare_number, names_celsius, parse_quantity, Dimension, UnitError};
use super::{field, Checker, Quantity};
use crate::job::echoed;
use crate::model::continuum::constrained_modulus;
use crate::model::spectrum::{wlf_decades, Terms, MAX_TERMS};
use crate::model::text::quantity;
use crate::model::{Layer, Parameter};
use crate::render::format_number;

/// How the layer gives way under the sphere (docs/model.md §8).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum LayerModel {
    /// The paper's local (Winkler) law: each point of the layer a spring, k = E_L/H. Exact
    /// for contacts much wider than the layer; the paper's model and its figures.
    #[default]
    Local,
    /// The layer as a viscoelastic solid bonded to a rigid base, solved on a grid: right at
    /// any width, and the answer for contacts a few thicknesses wide or narrower, where the
    /// local law overstates the area (the `local_layer` validity row says by how much).
    /// Rolling jobs and their sweeps; milliseconds to a second per answer.
    Continuum,
}

/// One term of a Prony series: E_j e^{−t/τ_j} of the relaxation modulus.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct PronyTerm {
    /// E_j (Pa, > 0). Required.
    pub modulus: Option<Quantity>,
    /// τ_j (s, > 0). Required.
    pub time: Option<Quantity>,
}

/// The time–temperature shift of Williams, Landel and Ferry: at temperature T every time of
/// the series is multiplied by a_T, log₁₀ a_T = −C₁(T − T_ref)/(C₂ + T − T_ref).
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct WlfInput {
    /// T_ref, where the series' times hold (K, or a string in °C such as "25 °C").
    pub reference_temperature: Option<Quantity>,
    /// C₁ (dimensionless, > 0; 17.44 is the "universal" value).
    pub c1: Option<Quantity>,
    /// C₂ (K, > 0; a temperature difference, so in K: 51.6 is the "universal" value).
    pub c2: Option<Quantity>,
}

/// The layer: the paper's Kelvin layer (T_ε, T_σ), or a Prony series from material data.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct LayerInput {
    /// How the layer gives way: `local` (default, the paper's law) or `continuum`.
    pub model: Option<LayerModel>,
    /// E_L, the relaxed constrained (oedometric, longitudinal) modulus, not Young's E (Pa;
    /// default 3 GPa); with a Prony series its E_∞. It is the paper's spring constant per
    /// thickness, k = E_L/H.
    pub elastic_modulus: Option<Quantity>,
    /// E, the relaxed Young's modulus (Pa), instead of `elastic_modulus`: a DMA's or a
    /// datasheet's modulus, read as E_L = E (1 − ν)/((1 + ν)(1 − 2ν)) (1.6 E at ν = 0.35;
    /// docs/model.md §8). Not with `elastic_modulus`.
    pub youngs_modulus: Option<Quantity>,
    /// H, layer thickness (m; default 100 nm).
    pub thickness: Option<Quantity>,
    /// ν, Poisson ratio (dimensionless; default 0.35).
    pub poisson_ratio: Option<Quantity>,
    /// T_ε, retardation time (s, ≥ T_σ; default 0.5 s). Not with a Prony series.
    pub retardation_time: Option<Quantity>,
    /// T_σ, relaxation time (s; default 0.1 s). Not with a Prony series.
    pub relaxation_time: Option<Quantity>,
    /// A Prony series instead of (T_ε, T_σ): E(t) = E_∞ + Σ E_j e^{−t/τ_j}, E_∞ being
    /// `elastic_modulus` (docs/model.md §9). 1 to 24 terms.
    pub prony: Option<Vec<PronyTerm>>,
    /// The same series as CSV text, a row (τ_j, E_j) per term: numbers in s and Pa, or
    /// quantities with units ("100 ms", "12 GPa"); comma, semicolon or tab separated. A
    /// first row with no cell starting with a number is a header, which may name its
    /// columns' units as "tau [ms]", "tau (ms)", "tau/ms" or "tau_ms": the units of their
    /// bare numbers (a unit it names that cannot be read is refused).
    pub prony_csv: Option<String>,
    /// Shift the times from `wlf.reference_temperature` to `temperature` (WLF).
    pub wlf: Option<WlfInput>,
    /// T, the layer's temperature in this job (K, or "40 °C"); needs `wlf`.
    pub temperature: Option<Quantity>,
}

impl LayerInput {
    /// Reads the layer under `checker` (inside its `nested` object).
    pub fn read(&self, checker: &mut Checker) -> Layer {
        let input = self;
        let d = Layer::default();
        let youngs = self.youngs(checker);
        let given = checker.quantity(
            field!(input.elastic_modulus),
            Parameter::ElasticModulus,
            d.elastic_modulus,
        );
        let thickness =
            checker.quantity(field!(input.thickness), Parameter::Thickness, d.thickness);
        let poisson_ratio = checker.quantity(
            field!(input.poisson_ratio),
            Parameter::PoissonRatio,
            d.poisson_ratio,
        );
        let elastic_modulus = match youngs {
            Some(e) => self.constrained(checker, e, poisson_ratio),
            None => given,
        };
        let layer = match self.series(checker) {
            Some(terms) => {
                for (field, given) in [
                    ("retardation_time", &self.retardation_time),
                    ("relaxation_time", &self.relaxation_time),
                ] {
                    if let Some(given) = given {
                        let allowed = "absent with a Prony series (its first term gives the times)";
                        checker.invalid(field, given.sent(), allowed);
                    }
                }
                Layer::from_prony(elastic_modulus, thickness, poisson_ratio, &terms).unwrap_or(d)
            }
            None => Layer {
                elastic_modulus,
                thickness,
                poisson_ratio,
                retardation_time: checker.quantity(
                    field!(input.retardation_time),
                    Parameter::RetardationTime,
                    d.retardation_time,
                ),
                relaxation_time: checker.quantity(
                    field!(input.relaxation_time),
                    Parameter::RelaxationTime,
                    d.relaxation_time,
                ),
                arms: Terms::default(),
            },
        };
        match self.shift(checker) {
            Some(decades) => layer.with_times_scaled(10f64.powf(decades)),
            None => layer,
        }
    }

    /// E, Young's modulus, when it is the modulus given (`youngs_modulus`, checked at its
    /// own field as sent, which the model's errors of E_L then name).
    fn youngs(&self, checker: &mut Checker) -> Option<f64> {
        let input = self;
        match (&self.elastic_modulus, &self.youngs_modulus) {
            (Some(_), Some(given)) => {
                let allowed = "absent with elastic_modulus (one modulus: E_L, constrained, \
                               or E, Young's)";
                checker.invalid("youngs_modulus", given.sent(), allowed);
                None
            }
            (None, Some(_)) => {
                checker.optional(field!(input.youngs_modulus), Parameter::ElasticModulus)
            }
            (_, None) => None,
        }
    }

    /// E_L from Young's `youngs` at `poisson_ratio` (docs/model.md §8). Not with a ν out of
    /// range, which is reported at its own field: E is kept as it is, so that it is not
    /// blamed for ν. An E_L beyond double precision is reported at `youngs_modulus`.
    fn constrained(&self, checker: &mut Checker, youngs: f64, poisson_ratio: f64) -> f64 {
        if Parameter::PoissonRatio.check(poisson_ratio).is_err() {
            return youngs;
        }
        let converted = constrained_modulus(youngs, poisson_ratio);
        if youngs.is_finite() && !converted.is_finite() {
            let factor = constrained_modulus(1.0, poisson_ratio);
            let allowed = format!(
                "at most {} at ν = {poisson_ratio}, where E_L = E(1 − ν)/((1 + ν)(1 − 2ν)) = \
                 {}·E must be a finite number",
                quantity(f64::MAX / factor, "Pa"),
                quantity(factor, "")
            );
            checker.out_of_range("youngs_modulus", youngs, "Pa", &allowed);
            return youngs;
        }
        converted
    }

    /// The Prony series (E_j, τ_j) given as `prony` or `prony_csv`, if any; a term out of
    /// range is reported at its own field and left out.
    fn series(&self, checker: &mut Checker) -> Option<Vec<(f64, f64)>> {
        let terms = match (&self.prony, &self.prony_csv) {
            (Some(_), Some(csv)) => {
                let allowed = "absent when prony is given (one series, one way)";
                checker.invalid("prony_csv", json!(csv), allowed);
                return None;
            }
            (Some(terms), None) => terms
                .iter()
                .enumerate()
                .filter_map(|(i, term)| {
                    checker.item("prony", i, term, |checker, term| {
                        let modulus =
                            checker.required(field!(term.modulus), Parameter::PronyModulus, "");
                        let time = checker.required(field!(term.time), Parameter::PronyTime, "");
                        let ok = [
                            ("modulus", Parameter::PronyModulus, modulus),
                            ("time", Parameter::PronyTime, time),
                        ]
                        .into_iter()
                        .fold(true, |ok, (name, parameter, x)| match parameter.check(x) {
                            Ok(()) => ok,
                            // Unreadable or missing: already reported.
                            Err(_) if x.is_nan() => false,
                            Err(e) => {
                                checker.out_of_range(name, x, parameter.unit(), &e.allowed);
                                false
                            }
                        });
                        ok.then_some((modulus, time))
                    })
                })
                .collect(),
            (None, Some(csv)) => read_csv(csv, checker)?,
            (None, None) => return None,
        };
        let count = self.prony.as_ref().map_or(terms.len(), Vec::len);
        let field = if self.prony.is_some() {
            "prony"
        } else {
            "prony_csv"
        };
        if count == 0 || count > MAX_TERMS {
            let allowed = format!("a series of 1 to {MAX_TERMS} terms");
            checker.invalid(field, json!(count), &allowed);
            return None;
        }
        Some(terms)
    }

    /// The WLF shift in decades, if asked for (`wlf` with `temperature`).
    fn shift(&self, checker: &mut Checker) -> Option<f64> {
        let input = self;
        if self.wlf.is_none() {
            if let Some(given) = &self.temperature {
                let allowed = "absent without wlf (a temperature shifts the times only by WLF)";
                checker.invalid("temperature", given.sent(), allowed);
            }
            return None;
        }
        let temperature = checker.required(
            field!(input.temperature),
            Parameter::Temperature,
            "with wlf",
        );
        let (reference, c1, c2) = checker.nested(field!(input.wlf), |checker, wlf: &WlfInput| {
            let reference = checker.required(
                field!(wlf.reference_temperature),
                Parameter::ReferenceTemperature,
                "",
            );
            let c1 = checker.required(field!(wlf.c1), Parameter::WlfC1, "");
            let c2 = checker.required(field!(wlf.c2), Parameter::WlfC2, "");
            if let Some(Quantity::Text(t)) = &wlf.c2 {
                if names_celsius(t) {
                    let allowed = "a temperature difference in K (a number, or \"51.6 K\")";
                    checker.invalid("c2", json!(t), allowed);
                }
            }
            for (name, parameter, x) in [
                (
                    "reference_temperature",
                    Parameter::ReferenceTemperature,
                    reference,
                ),
                ("c1", Parameter::WlfC1, c1),
                ("c2", Parameter::WlfC2, c2),
            ] {
                if let (false, Err(e)) = (x.is_nan(), parameter.check(x)) {
                    checker.out_of_range(name, x, parameter.unit(), &e.allowed);
                }
            }
            (reference, c1, c2)
        });
        if let (false, Err(e)) = (
            temperature.is_nan(),
            Parameter::Temperature.check(temperature),
        ) {
            checker.out_of_range("temperature", temperature, "K", &e.allowed);
        }
        if [temperature, reference, c1, c2]
            .iter()
            .any(|x| !x.is_finite())
        {
            return None;
        }
        let decades = wlf_decades(c1, c2, reference, temperature);
        if decades.is_none() {
            let allowed = format!(
                "above T_ref − C₂ = {} K, the pole of the WLF law",
                format_number(reference - c2)
            );
            checker.out_of_range("temperature", temperature, "K", &allowed);
        }
        decades
    }

    /// The input that gives `layer` under `model`: every field, in SI (`model` absent
    /// where only the local law is offered). A layer of more than one term is written as
    /// its Prony series, at the job's temperature (any WLF shift applied).
    pub fn of(layer: &Layer, model: Option<LayerModel>) -> LayerInput {
        let kelvin = layer.arms.is_empty();
        LayerInput {
            model,
            elastic_modulus: Quantity::si(layer.elastic_modulus),
            thickness: Quantity::si(layer.thickness),
            poisson_ratio: Quantity::si(layer.poisson_ratio),
            retardation_time: kelvin
                .then(|| Quantity::si(layer.retardation_time))
                .flatten(),
            relaxation_time: kelvin
                .then(|| Quantity::si(layer.relaxation_time))
                .flatten(),
            prony: (!kelvin).then(|| {
                layer
                    .prony()
                    .into_iter()
                    .map(|(modulus, time)| PronyTerm {
                        modulus: Quantity::si(modulus),
                        time: Quantity::si(time),
                    })
                    .collect()
            }),
            ..LayerInput::default()
        }
    }

    /// [`LayerInput::read`] where the layer's law is chosen elsewhere (a three-body
    /// system's `layer_contact`, named by `instead`): `model: "continuum"` is an error
    /// naming the field and saying where to ask.
    pub fn read_local(&self, checker: &mut Checker, instead: &str) -> Layer {
        if self.model == Some(LayerModel::Continuum) {
            checker.invalid(
                "model",
                "continuum".into(),
                &format!("\"local\" or absent: {instead}"),
            );
        }
        self.read(checker)
    }
}

/// The columns of a Prony series' CSV, in their order: each term's name, parameter and
/// dimension.
const COLUMNS: [(&str, Parameter, Dimension); 2] = [
    ("τ_j", Parameter::PronyTime, Dimension::TIME),
    ("E_j", Parameter::PronyModulus, Dimension::PRESSURE),
];

/// What the rows of a Prony series' CSV may be.
const ROWS: &str = "rows \"τ_j, E_j\" such as \"0.1, 12e9\" or \"100 ms, 12 GPa\"";

/// How a header may name its columns' units (README, "A layer from material data").
const HEADER: &str = "a header naming each column's unit as \"tau [ms]\", \"tau (ms)\", \
    \"tau/ms\" or \"tau_ms\" (an SI unit with an SI prefix: a time, then a pressure such as \
    \"E [GPa]\"), or no unit for numbers in s and Pa";

/// The rows (τ_j, E_j) of a Prony series as CSV text, as (E_j, τ_j); each bad cell is
/// reported once, naming its row, and the series is then `None`.
///
/// A first row of which no cell starts with a number is a header. A unit it names is the
/// unit of its column's bare numbers (a cell with a unit of its own keeps it), and a unit it
/// names that cannot be read refuses the series: a header `tau [min]` or `E_psi` ignored would
/// read its rows as seconds and pascals, a silently wrong answer. Bare numbers under no unit
/// are SI, warned of where far from their column's scale as a bare number in a field is.
fn read_csv(csv: &str, checker: &mut Checker) -> Option<Vec<(f64, f64)>> {
    let mut rows = csv
        .lines()
        .enumerate()
        .filter(|(_, line)| !line.trim().is_empty())
        .map(|(i, line)| (i + 1, line.split([',', ';', '\t']).map(str::trim).collect()))
        .peekable();
    let is_header = |cells: &Vec<&str>| {
        cells
            .iter()
            .all(|cell| parse_quantity(cell, Dimension::NONE) == Err(UnitError::NoNumber))
    };
    let units = match rows.next_if(|(_, cells)| is_header(cells)) {
        Some((line, cells)) => header_units(checker, line, &cells)?,
        None => [None; 2],
    };
    let mut terms = Vec::new();
    let mut bad = false;
    let mut refuse = |checker: &mut Checker, line, cells: &[&str], what| {
        complain(checker, line, cells, what, ROWS);
        bad = true;
    };
    for (line, cells) in rows {
        if cells.len() != COLUMNS.len() {
            refuse(checker, line, &cells, format!("{} cells", cells.len()));
            continue;
        }
        let mut term = [f64::NAN; 2];
        for ((x, (cell, unit)), (name, parameter, dimension)) in
            term.iter_mut().zip(cells.iter().zip(units)).zip(COLUMNS)
        {
            let bare = is_bare_number(cell);
            let read = match unit {
                Some(unit) if bare => parse_quantity(&format!("{cell} {unit}"), dimension),
                _ => parse_quantity(cell, dimension),
            };
            match read {
                Ok(value) if parameter.check(value).is_ok() => {
                    if bare && unit.is_none() {
                        let place = format!("row {line}, {name}");
                        checker.bare_cell("prony_csv", &place, cell, parameter, value);
                    }
                    *x = value;
                }
                Ok(value) => {
                    let what = format!(
                        "{parameter} {} is out of range ({})",
                        format_number(value),
                        parameter.allowed()
                    );
                    refuse(checker, line, &cells, what);
                }
                Err(e) => refuse(checker, line, &cells, format!("\"{}\" {e}", echoed(cell))),
            }
        }
        if term.iter().all(|x| x.is_finite()) {
            terms.push((term[1], term[0]));
        }
    }
    (!bad).then_some(terms)
}

/// The unit of each column a CSV's header names (`None`: no unit, SI); `None` after
/// reporting a header that cannot be read, whose rows then cannot be either.
fn header_units<'a>(
    checker: &mut Checker,
    line: usize,
    cells: &[&'a str],
) -> Option<[Option<&'a str>; 2]> {
    let mut bad = cells.len() != COLUMNS.len();
    if bad {
        let what = format!("a header of {} cells", cells.len());
        complain(checker, line, cells, what, HEADER);
    }
    let mut units = [None; 2];
    for ((unit, cell), (name, _, dimension)) in units.iter_mut().zip(cells).zip(COLUMNS) {
        *unit = header_unit(cell);
        let Some(named) = unit else { continue };
        if let Err(e) = parse_quantity(&format!("1 {named}"), dimension) {
            let e = match e {
                UnitError::WrongDimension { found, .. } => {
                    format!("names {found}, and its column holds {name}, {dimension}")
                }
                e => e.to_string(),
            };
            let what = format!("the header's \"{}\" {e}", echoed(cell));
            complain(checker, line, cells, what, HEADER);
            bad = true;
        }
    }
    (!bad).then_some(units)
}

/// Reports row `line` of `prony_csv` (its `cells`): `what` is wrong with it, `expected` is
/// what it may be.
fn complain(checker: &mut Checker, line: usize, cells: &[&str], what: String, expected: &str) {
    let allowed = format!("row {line}: {what}; expected {expected}");
    checker.invalid("prony_csv", json!(cells.join(",")), &allowed);
}

/// The unit a header cell names: `tau [ms]`, `tau (ms)`, `tau/ms` (a quantity over its unit,
/// as the SI brochure labels a table's column) or `tau_ms`; `None` for a name alone (`tau`).
fn header_unit(cell: &str) -> Option<&str> {
    let bracketed = [('[', ']'), ('(', ')')]
        .into_iter()
        .find_map(|(open, close)| {
            let (_, unit) = cell.strip_suffix(close)?.rsplit_once(open)?;
            Some(unit)
        });
    bracketed
        .or_else(|| cell.rsplit_once(['/', '_']).map(|(_, unit)| unit))
        .map(str::trim)
        .filter(|unit| !unit.is_empty())
}
