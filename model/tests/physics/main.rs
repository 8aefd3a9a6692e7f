//! The physics core against its closed forms, the reference table and its stated trends:
//! one test binary, a module per concern.

mod continuum;
mod continuum_rolling;
mod honest_edges;
mod numerical_honesty;
mod prony;
mod reference_table;
mod rolling_limits;
mod similarity;
mod three_body_continuum;
mod trends;
