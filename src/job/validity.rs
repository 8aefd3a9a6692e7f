//! The domain of validity in an answer (docs/model.md §7): each assumption of the model with its
//! ratio and status, in `meta.validity` (and per sweep point); a violated assumption refuses
//! the answer with a message naming the cause and the numbers.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::JobError;
use crate::described;
use crate::model::motion::Mode;
use crate::model::text::{count, quantity};
use crate::model::validity::{Assumption, Check, Status};
use crate::render::{Fixed, Text};

/// `ok`, or `warn`: the answer is given, and a note says why it may be off.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize, ToSchema,
)]
#[serde(rename_all = "lowercase")]
pub enum ValidityStatus {
    #[default]
    Ok,
    Warn,
}

described! {
    /// One assumption of the model, measured on this answer.
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct AssumptionOutput {
        /// `inside_layer`, `parabolic_sphere`, `local_layer`, `adhesive_friction`,
        /// `surfaces_apart`, `asperity_gap`, `particles_in_contact`, `pure_rolling` or (the
        /// layer as a continuum) `resolution` and `numerical`.
        pub name: &'static str => [],
        /// The assumption in words.
        #[schema(value_type = String)]
        pub assumption: &'static Text => [],
        /// What the ratio measures, e.g. `penetration / thickness`.
        pub ratio: &'static str => [],
        /// The ratio at the job's speed (dimensionless).
        pub value: f64 => [unit ""],
        /// The ratio of the V = 0 companion the answer also gives (dimensionless).
        pub at_rest: f64 => [unit ""],
        /// The worse of the two.
        pub status: ValidityStatus => [],
        /// When the ratio warns and when it refuses the answer.
        #[schema(value_type = String)]
        pub rule: &'static Text => [],
        /// Why it warns, in words (with `warn` only).
        #[serde(skip_serializing_if = "Option::is_none")]
        pub note: Option<String> => [],
    }
}

described! {
    /// The model's own error on this answer (the `verification` block gives the numerical
    /// error).
    #[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
    pub struct ValidityOutput {
        /// The worst status of the assumptions.
        pub status: ValidityStatus => [],
        pub assumptions: Vec<AssumptionOutput> => [each],
    }
}

/// What the checks are measured on, for their words.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Subject {
    /// One particle rolling over the layer.
    Particle,
    /// A three-body system, measured on its largest particle in contact.
    System,
}

/// The validity block of `checks`, or the error of the first violated one.
pub fn assess(checks: &[Check], subject: Subject) -> Result<ValidityOutput, JobError> {
    if let Some(check) = checks.iter().find(|c| c.status() == Status::Violated) {
        return Err(JobError::OutOfDomain(violation(check, subject)));
    }
    let assumptions: Vec<AssumptionOutput> = checks.iter().map(|c| output(c, subject)).collect();
    let status = assumptions
        .iter()
        .map(|a| a.status)
        .max()
        .unwrap_or(ValidityStatus::Ok);
    Ok(ValidityOutput {
        status,
        assumptions,
    })
}

/// The names of the assumptions that warn, for a CSV cell: `ok`, or `warn: local_layer`.
pub fn summary(validity: &ValidityOutput) -> String {
    let warned: Vec<&str> = validity
        .assumptions
        .iter()
        .filter(|a| a.status == ValidityStatus::Warn)
        .map(|a| a.name)
        .collect();
    if warned.is_empty() {
        "ok".to_string()
    } else {
        format!("warn: {}", warned.join(" "))
    }
}

/// A compact validity of one point of a sweep: each assumption's ratio at the point's speed,
/// by name (`validity`), and the names of those that warn, at the point's speed or at rest
/// (`warn`). The words, rules and notes are in the sweep's `meta.validity`, once
/// ([`ValidityTally`]): written on every point they were two thirds of a sweep's bytes.
#[derive(Clone, Debug, PartialEq)]
pub struct PointValidity {
    checks: Vec<Check>,
    /// Bit `i` set: `checks[i]` warns (measured once: a row asks for it several times).
    warned: u16,
}

impl PointValidity {
    /// The validity of a point measured by `checks`, or the reason it is refused (the first
    /// violated assumption, in words).
    pub fn assess(checks: Vec<Check>, subject: Subject) -> Result<PointValidity, JobError> {
        let mut warned = 0;
        for (i, check) in checks.iter().enumerate() {
            match check.status() {
                Status::Violated => return Err(JobError::OutOfDomain(violation(check, subject))),
                Status::Warn => warned |= 1 << i,
                Status::Ok => {}
            }
        }
        Ok(PointValidity { checks, warned })
    }

    /// The worst status of the assumptions.
    pub fn status(&self) -> ValidityStatus {
        if self.warned == 0 {
            ValidityStatus::Ok
        } else {
            ValidityStatus::Warn
        }
    }

    /// The checks that warn.
    fn warning(&self) -> impl Iterator<Item = &Check> + '_ {
        let warned = self.warned;
        self.checks
            .iter()
            .enumerate()
            .filter(move |(i, _)| warned & (1 << i) != 0)
            .map(|(_, c)| c)
    }

    /// The names of the assumptions that warn.
    pub fn warned(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.warning().map(|c| described(c.assumption).name)
    }

    /// The names of the assumptions that warn, as a CSV cell (space-separated), appended to
    /// `text`.
    pub fn write_warned(&self, text: &mut String) {
        for (i, name) in self.warned().enumerate() {
            if i > 0 {
                text.push(' ');
            }
            text.push_str(name);
        }
    }
}

impl PointValidity {
    /// The path and unit of each ratio a point may give (the serialization below).
    pub fn units() -> Vec<(String, &'static str)> {
        DESCRIBED.iter().map(|d| (d.name.to_string(), "")).collect()
    }
}

/// `{"inside_layer": 0.0062, ...}`: each ratio at the point's speed.
impl Serialize for PointValidity {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = s.serialize_map(Some(self.checks.len()))?;
        for check in &self.checks {
            map.serialize_entry(described(check.assumption).name, &check.ratio())?;
        }
        map.end()
    }
}

/// How the points of a sweep stand against each assumption, for its `meta.validity`: the
/// assumption in words once, how many answered points it warns on, and the note of the
/// first of them. Tallies of consecutive ranges of points merge into the tally of the
/// whole ([`ValidityTally::merge`]), so that a sweep solved in parts says the same as one
/// solved whole.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ValidityTally {
    assumptions: Vec<Tally>,
}

#[derive(Clone, Debug, PartialEq)]
struct Tally {
    assumption: Assumption,
    warned: usize,
    /// The first point that warns: its index in the sweep and the note.
    first: Option<(usize, String)>,
}

impl Tally {
    /// Point `index` warns: its note is kept if it comes before the first one seen.
    fn offer(&mut self, index: usize, note: impl FnOnce() -> String) {
        if self.first.as_ref().is_none_or(|(i, _)| index < *i) {
            self.first = Some((index, note()));
        }
    }
}

impl ValidityTally {
    /// Counts point `index`, measured as `validity`.
    pub fn count(&mut self, index: usize, validity: &PointValidity, subject: Subject) {
        for check in &validity.checks {
            self.tally(check.assumption);
        }
        for check in validity.warning() {
            let tally = self.tally(check.assumption);
            tally.warned += 1;
            tally.offer(index, || note(check, subject));
        }
    }

    fn tally(&mut self, assumption: Assumption) -> &mut Tally {
        let at = match self
            .assumptions
            .iter()
            .position(|t| t.assumption == assumption)
        {
            Some(at) => at,
            None => {
                self.assumptions.push(Tally {
                    assumption,
                    warned: 0,
                    first: None,
                });
                self.assumptions.len() - 1
            }
        };
        &mut self.assumptions[at]
    }

    /// Adds the tally of other points.
    pub fn merge(&mut self, other: ValidityTally) {
        for theirs in other.assumptions {
            let ours = self.tally(theirs.assumption);
            ours.warned += theirs.warned;
            if let Some((index, note)) = theirs.first {
                ours.offer(index, || note);
            }
        }
    }

    /// `warn` if any point warns.
    pub fn status(&self) -> ValidityStatus {
        if self.assumptions.iter().any(|t| t.warned > 0) {
            ValidityStatus::Warn
        } else {
            ValidityStatus::Ok
        }
    }
}

described! {
    /// One assumption of a sweep's `meta.validity`.
    #[derive(Serialize, Deserialize, ToSchema)]
    pub struct AssumptionTallyOutput {
        /// As in a rolling answer's `meta.validity`: `inside_layer`, `local_layer`, ...
        name: String => [],
        /// The assumption in words.
        #[serde(skip_deserializing, default = "no_text")]
        #[schema(value_type = String)]
        assumption: &'static Text => [],
        /// What the ratio of each point's `validity` measures.
        #[serde(skip_deserializing)]
        ratio: &'static str => [],
        /// When the ratio warns and when it refuses a point.
        #[serde(skip_deserializing, default = "no_text")]
        #[schema(value_type = String)]
        rule: &'static Text => [],
        /// Answered points on which it warns (count).
        warned: usize => [unit ""],
        /// The index of the first of them.
        #[serde(skip_serializing_if = "Option::is_none")]
        first_warned: Option<usize> => [unit ""],
        /// Why it warns there, in words.
        #[serde(skip_serializing_if = "Option::is_none")]
        note: Option<String> => [],
    }
}

/// The text of a tally read back from another process (which reads only its counts).
fn no_text() -> &'static Text {
    static NONE: Text = Fixed::new("");
    &NONE
}

described! {
    /// The model's assumptions over the answered points of a sweep (docs/model.md §7): each in
    /// words once, how many points it warns on, and why it warns on the first of them.
    #[derive(Serialize, Deserialize, ToSchema)]
    pub struct SweepValidityOutput {
        /// `warn` if any answered point warns, or the model refused a point.
        #[serde(skip_deserializing)]
        status: ValidityStatus => [],
        assumptions: Vec<AssumptionTallyOutput> => [each],
    }
}

impl ValidityTally {
    /// The tally as written; `refused` says whether the model refused points of the sweep,
    /// which makes its status `warn` too.
    pub fn output(&self, refused: bool) -> SweepValidityOutput {
        let status = if refused {
            ValidityStatus::Warn
        } else {
            self.status()
        };
        SweepValidityOutput {
            status,
            assumptions: self
                .assumptions
                .iter()
                .map(|t| {
                    let described = described(t.assumption);
                    AssumptionTallyOutput {
                        name: described.name.to_string(),
                        assumption: &described.assumption,
                        ratio: described.ratio,
                        rule: &described.rule,
                        warned: t.warned,
                        first_warned: t.first.as_ref().map(|(i, _)| *i),
                        note: t.first.as_ref().map(|(_, note)| note.clone()),
                    }
                })
                .collect(),
        }
    }
}

/// Reads back what [`ValidityTally`] wrote (a part of a sweep solved in another process).
impl<'de> Deserialize<'de> for ValidityTally {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let written = SweepValidityOutput::deserialize(d)?;
        let assumptions = written
            .assumptions
            .into_iter()
            .map(|t| {
                let assumption = Assumption::ALL
                    .into_iter()
                    .find(|a| described(*a).name == t.name)
                    .ok_or_else(|| {
                        serde::de::Error::custom(format!("no assumption is named {}", t.name))
                    })?;
                Ok(Tally {
                    assumption,
                    warned: t.warned,
                    first: t.first_warned.zip(t.note),
                })
            })
            .collect::<Result<_, D::Error>>()?;
        Ok(ValidityTally { assumptions })
    }
}

/// A length as people read it: 651 nm, 5.58 nm, 2.1 µm.
fn length(x: f64) -> String {
    quantity(x, "m")
}

/// An area as people read it: 13.4 nm².
fn area(x: f64) -> String {
    quantity(x, "m^2")
}

/// A plain number (a ratio, a percentage, a friction coefficient) to three digits.
fn significant(x: f64) -> String {
    quantity(x, "")
}

/// An assumption as answers describe it: its name, what its ratio measures, and the
/// assumption and its rule in words (fixed texts, their JSON rendered once).
struct Described {
    name: &'static str,
    assumption: Text,
    ratio: &'static str,
    rule: Text,
}

impl Described {
    const fn new(
        name: &'static str,
        assumption: &'static str,
        ratio: &'static str,
        rule: &'static str,
    ) -> Described {
        Described {
            name,
            assumption: Fixed::new(assumption),
            ratio,
            rule: Fixed::new(rule),
        }
    }
}

/// Each assumption described, in the order of [`Assumption::ALL`].
static DESCRIBED: [Described; 10] = [
    Described::new(
        "inside_layer",
        "the sphere stays inside the layer: the rigid base is never reached",
        "penetration / thickness",
        "warn above 0.1 (the linear layer law assumes small strain); refused at 1",
    ),
    Described::new(
        "parabolic_sphere",
        "the sphere is a paraboloid near the contact (contact an order smaller than R)",
        "contact extent / radius",
        "warn when (ratio)²/4, the profile's error, passes 0.05; refused at 1",
    ),
    Described::new(
        "local_layer",
        "the layer is local (Winkler): each point of it gives way alone, as under a contact \
         much wider than a compressible layer",
        "contact area at rest under the local law / that of the layer as a continuum",
        "warn when off by more than 5 % either way",
    ),
    Described::new(
        "adhesive_friction",
        "adhesive friction τ_a A / P (eq. 12) is meaningful",
        "friction coefficient",
        "warn above 1",
    ),
    Described::new(
        "surfaces_apart",
        "the surfaces stay apart (the paper's always-a-gap regime)",
        "separation / largest diameter",
        "refused at or below 0",
    ),
    Described::new(
        "asperity_gap",
        "the asperities of the surfaces stay apart",
        "separation / asperity height standard deviation",
        "warn below 3",
    ),
    Described::new(
        "particles_in_contact",
        "at least one particle is in contact",
        "particles in contact",
        "warn below 1",
    ),
    Described::new(
        "resolution",
        "the grid of the layer as a continuum resolves the contact",
        "pixels across the contact on the fine grid",
        "warn below 24",
    ),
    Described::new(
        "numerical",
        "the answer is as exact as docs/model.md §8 asks: 1 % in A (and μ), 0.5 % in δ",
        "reported error / tolerance, the larger of A's and δ's",
        "warn above 1",
    ),
    Described::new(
        "pure_rolling",
        "the particles roll, as the paper assumes: both contacts transmit the tangential \
         force rolling needs (docs/model.md §11)",
        "tangential force rolling needs / the most the weaker contact transmits (three-body: \
         the particle furthest from rolling)",
        "warn above 1 (the particle slides at the weaker contact)",
    ),
];

fn described(assumption: Assumption) -> &'static Described {
    let index = Assumption::ALL.iter().position(|a| *a == assumption);
    &DESCRIBED[index.expect("Assumption::ALL lists every assumption")]
}

fn output(check: &Check, subject: Subject) -> AssumptionOutput {
    let described = described(check.assumption);
    let status = match check.status() {
        Status::Ok => ValidityStatus::Ok,
        _ => ValidityStatus::Warn,
    };
    AssumptionOutput {
        name: described.name,
        assumption: &described.assumption,
        ratio: described.ratio,
        value: check.ratio(),
        at_rest: check.ratio_at_rest(),
        status,
        rule: &described.rule,
        note: (status == ValidityStatus::Warn).then(|| note(check, subject)),
    }
}

/// The state that decides a check's status, in words, and its numbers.
fn state(check: &Check) -> (&'static str, (f64, f64)) {
    if check.caused_at_rest() {
        (
            "at rest (V = 0, the `static` companion the answer also gives), ",
            check.at_rest,
        )
    } else {
        ("", check.rolling)
    }
}

fn whose(subject: Subject) -> &'static str {
    match subject {
        Subject::Particle => "the",
        Subject::System => "the largest particle's",
    }
}

/// Why a check warns, in a user's words.
fn note(check: &Check, subject: Subject) -> String {
    use Assumption::*;
    let (when, (value, reference)) = state(check);
    let ratio = value / reference;
    match check.assumption {
        InsideLayer => format!(
            "{when}{} penetration {} is {}% of the layer's thickness {}: the linear layer law \
             assumes small strain",
            whose(subject),
            length(value),
            significant(100.0 * ratio),
            length(reference)
        ),
        Parabolic => format!(
            "{when}the contact extends to {} of the radius {}: the parabolic profile errs by \
             about {}%",
            length(value),
            length(reference),
            significant(25.0 * ratio * ratio)
        ),
        LocalLayer => {
            let (how, why) = if ratio > 1.0 {
                (
                    "overstates",
                    "the layer spreads the load over about its thickness, which the local law \
                     ignores. The paper's own parameters are in this regime",
                )
            } else {
                (
                    "understates",
                    "a thin, nearly incompressible layer squeezes out sideways, which the local \
                     law's springs cannot",
                )
            };
            let instead = match subject {
                Subject::Particle => {
                    ". For the answer of the layer as a continuum, ask for \"layer\": \
                     {\"model\": \"continuum\"}"
                }
                Subject::System => "",
            };
            format!(
                "at rest {} contact area is {} under the local (Winkler) law but {} with the \
                 layer as a continuum bonded to its base (docs/model.md §8): the local law \
                 {how} it {}×, and μ = τ_a A / P with it; {why}{instead}",
                whose(subject),
                area(value),
                area(reference),
                significant(ratio)
            )
        }
        AdhesiveFriction => format!(
            "{when}μ = {} is above 1: the load is too small for τ_a A / P to be a friction \
             coefficient",
            significant(value)
        ),
        SurfacesApart => String::new(),
        AsperityGap => format!(
            "{when}the separation {} is {} times the asperities' height spread {}: the \
             asperities touch and their contact (Zhao–Maietta–Chang) is in the answer, outside \
             the paper's always-a-gap regime",
            length(value),
            significant(ratio),
            length(reference)
        ),
        ParticlesInContact => format!(
            "{when}only {} are in contact, fewer than one: the means per particle describe \
             a fraction of a particle",
            count(value, "particle", "particles")
        ),
        Resolution => format!(
            "{when}the contact is {} pixels across on the grid: the place of its edges within \
             their pixels limits the area's accuracy (`meta.verification` gives its error)",
            significant(value)
        ),
        Numerical => format!(
            "{when}the reported error is {} times the tolerance (1 % in A and μ, 0.5 % in δ): \
             the numbers are less exact than that, by the bounds in `meta.verification`",
            significant(value)
        ),
        PureRolling => sliding(check, subject),
    }
}

/// Why a pure-rolling check warns: which contact gives way, by how much, and the friction
/// the particles then transmit.
fn sliding(check: &Check, subject: Subject) -> String {
    let Some(sliding) = check.motion else {
        return String::new();
    };
    let m = &sliding.motion;
    let (contact, slides) = match m.mode {
        Mode::SlidesAtUpper => ("upper surface", "against the upper surface"),
        _ => ("layer", "on the layer"),
    };
    let share = format!(
        "its contact with the {contact} can transmit only {} % of the tangential force \
         rolling needs ({} against μ_roll = (μ_r,upper + μ_r,layer)/2 = {})",
        significant(100.0 / check.ratio()),
        significant(check.rolling.1),
        significant(m.rolling_need),
    );
    match (subject, sliding.particles) {
        (Subject::System, Some((slide, all))) => format!(
            "{} of the {} in contact slide instead of rolling; the one furthest from rolling \
             slides {slides}: {share}. With each particle's own motion the system's friction \
             is {} (`motion.friction`), not eq. 12's (docs/model.md §11)",
            count(slide, "", "").trim_end(),
            count(all, "particle", "particles"),
            significant(sliding.friction),
        ),
        _ => format!(
            "the particle slides {slides} instead of rolling: {share}. Its friction is then \
             that capacity, {} (`motion.friction`), where the paper assumes it rolls \
             (docs/model.md §11)",
            significant(sliding.friction),
        ),
    }
}

/// Why a violated check refuses the answer, with its numbers.
fn violation(check: &Check, subject: Subject) -> String {
    use Assumption::*;
    let (when, (value, reference)) = state(check);
    let rest = if check.caused_at_rest() {
        " (the rolling contact stays inside the model's domain, but the answer carries both)"
    } else {
        ""
    };
    let cause = match check.assumption {
        InsideLayer => format!(
            "{} penetration {} reaches the layer's thickness {}: the sphere would touch the \
             rigid base",
            whose(subject),
            length(value),
            length(reference)
        ),
        Parabolic => format!(
            "the contact's extent {} reaches the sphere's radius {}: the contact is not small \
             compared with the sphere",
            length(value),
            length(reference)
        ),
        SurfacesApart => format!(
            "the separation {} is not positive: the surfaces touch, outside the three-body model",
            length(value)
        ),
        LocalLayer | AdhesiveFriction | AsperityGap | ParticlesInContact | Resolution
        | Numerical | PureRolling => note(check, subject),
    };
    format!("{when}{cause}{rest}")
}
