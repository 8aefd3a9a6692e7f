//! The physics core against its closed forms, the reference table and its stated trends:
//! one test binary, a module per concern.

mod continuum;
mod continuum_rolling;
mod honest_edges;
mod motion;
mod numerical_honesty;
mod prony;
mod reference_table;
mod rolling_limits;
mod similarity;
mod three_body_continuum;
mod trends;

use thirdbody_model::Quadrature;

/// The Gauss rules of these node counts, then the midpoint rules of these strip counts.
fn rules(gauss_nodes: &[usize], midpoint_strips: &[usize]) -> Vec<Quadrature> {
    let gauss = gauss_nodes.iter().map(|&nodes| Quadrature::Gauss { nodes });
    let midpoint = midpoint_strips
        .iter()
        .map(|&strips| Quadrature::Midpoint { strips });
    gauss.chain(midpoint).collect()
}
