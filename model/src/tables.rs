//! The process's similarity tables ([`SimilarityTable`]), one per κ and strip rule: built
//! once from the exact strip solver, shared by every answer that uses that layer, and
//! bounded in number.
//!
//! Building a table costs about 5 ms for κ ≤ 100, as much as some 220 exact solves at a given
//! load (BENCHMARKS.md), so who builds when is the caller's choice ([`Use`]): a large sweep or
//! a figure builds at once; a single rolling answer always solves exactly, so that its digits
//! do not depend on the tables earlier jobs of the process built.

use std::sync::{Arc, Mutex, OnceLock};

use super::rolling::{penetration_contact, solve_with};
use super::similarity::SimilarityTable;
use super::spectrum::Terms;
use super::{Layer, ModelError, Quadrature, Rolling, RollingSolution, SolveOptions};

/// Tables kept at once; the least recently used goes beyond this. A table holds 55–80 kB
/// (its panels' coefficients), so at most ≈ 2.5 MB.
const KEPT_TABLES: usize = 32;

/// The table of κ under `quadrature`, if this process has built it.
pub fn built(kappa: f64, quadrature: Quadrature) -> Option<Arc<SimilarityTable>> {
    let mut tables = lock();
    let position = tables
        .iter()
        .position(|(key, _)| *key == (kappa.to_bits(), quadrature))?;
    let table = tables[position].1.clone();
    if position + 1 < tables.len() {
        let entry = tables.remove(position);
        tables.push(entry);
    }
    Some(table)
}

/// The table of κ > 0 under `quadrature`, built now if this process has not built it yet.
pub fn get_or_build(
    kappa: f64,
    quadrature: Quadrature,
) -> Result<Arc<SimilarityTable>, ModelError> {
    if let Some(table) = built(kappa, quadrature) {
        return Ok(table);
    }
    // Fail on an invalid rule before building.
    quadrature.check().map_err(ModelError::InvalidOption)?;
    let table = Arc::new(SimilarityTable::build(kappa, |xi| {
        penetration_contact(&Terms::one(kappa, xi), quadrature)
    })?);
    let mut tables = lock();
    let key = (kappa.to_bits(), quadrature);
    if let Some((_, kept)) = tables.iter().find(|(k, _)| *k == key) {
        return Ok(kept.clone()); // built meanwhile by another thread
    }
    if tables.len() >= KEPT_TABLES {
        tables.remove(0);
    }
    tables.push((key, table.clone()));
    Ok(table)
}

/// The table of a layer's whole Prony series under `quadrature`, indexed by its Kelvin term's
/// ξ = V T_σ/√(2Rδ) (every term's V τ_j/√(2Rδ) is ξ τ_j/T_σ, so one variable still fixes
/// the contact). Not kept: its key would be the whole series, which a three-body solve
/// builds once for all its sizes. Its certified error says how well one table's points
/// follow the series.
pub fn of_series(layer: &Layer, quadrature: Quadrature) -> Result<SimilarityTable, ModelError> {
    quadrature.check().map_err(ModelError::InvalidOption)?;
    let terms = layer.terms();
    SimilarityTable::build(layer.stiffening() - 1.0, |xi| {
        penetration_contact(&terms.scaled(xi / layer.relaxation_time), quadrature)
    })
}

/// How a rolling solve may use the similarity tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Use {
    /// Strip sums only.
    Exact,
    /// The layer's table, built now if need be.
    Build,
}

impl Use {
    /// Solves from which a job builds its layer's table. A table costs about 220 exact
    /// solves to build, but it is kept for every later job on the layer (a sweep is rarely
    /// alone), so jobs smaller than that build it too.
    const TABLE_COST: usize = 64;

    /// For a job of `solves` rolling solves on one layer under `quadrature`: build its
    /// table when the job is large enough ([`Use::TABLE_COST`]) and the rule is the default
    /// one (see [`solve`]), solve exactly otherwise. A function of the job alone, so that every
    /// part of a split job decides alike.
    pub fn for_solves(solves: usize, quadrature: Quadrature) -> Use {
        if solves >= Self::TABLE_COST && quadrature == Quadrature::default() {
            Use::Build
        } else {
            Use::Exact
        }
    }
}

/// The largest certified error ([`SimilarityTable::error`]) with which a table answers a
/// rolling job: a table is good to ≈ 1e-13 for κ ≤ 1e4 (tests/physics/similarity.rs) but less for
/// stronger viscosity, where the exact solve answers instead.
const ACCEPTED_TABLE_ERROR: f64 = 1e-10;

/// Solves `rolling` ([`super::rolling::solve`]), through the layer's similarity table as
/// `tables` allows. Only the default rule is tabulated for rolling answers (a job that
/// chooses its rule gets that rule's strip sums), and a layer without viscosity (κ = 0)
/// needs no table.
pub fn solve(
    rolling: &Rolling,
    options: &SolveOptions,
    tables: Use,
) -> Result<RollingSolution, ModelError> {
    let kappa = rolling.layer.kappa();
    let table = match tables {
        _ if !tabulable(rolling, options) => None,
        Use::Exact => None,
        // Never build for an invalid input: its solve reports what is wrong.
        Use::Build => match built(kappa, options.quadrature) {
            None if rolling.violations().is_empty() => {
                Some(get_or_build(kappa, options.quadrature)?)
            }
            found => found,
        },
    }
    .filter(|table| table.error() <= ACCEPTED_TABLE_ERROR);
    solve_with(rolling, options, table.as_deref())
}

/// Whether a rolling job may be answered through a table at all: its layer is a viscous
/// Kelvin layer (a table is one κ's: a Prony series of more terms is solved by strip sums),
/// and it keeps the default rule (a job that names its own rule is studying that rule's
/// strip sums).
fn tabulable(rolling: &Rolling, options: &SolveOptions) -> bool {
    rolling.layer.kappa() > 0.0
        && rolling.layer.arms.is_empty()
        && options.quadrature == Quadrature::default()
}

/// A table under its key: κ (its bits) and the strip rule.
type Entry = ((u64, Quadrature), Arc<SimilarityTable>);

/// The tables, least recently used first. They hold only immutable data, so a poisoned lock
/// is still consistent.
fn lock() -> std::sync::MutexGuard<'static, Vec<Entry>> {
    static TABLES: OnceLock<Mutex<Vec<Entry>>> = OnceLock::new();
    TABLES
        .get_or_init(|| Mutex::new(Vec::new()))
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}
