//! The answer assembled: inputs checked, the contact solved in units of r₀ (by strip sums or
//! through a similarity table), then scaled to SI units with its boundary and pressure, and
//! refused if any number is not finite.

use std::f64::consts::{FRAC_PI_4, PI};
use std::sync::Arc;

use super::load::{load_root, log_bracket, Shape, ELASTIC_SLOPE};
use super::problem::{Rolling, SolveOptions};
use super::section::{Section, ERROR_SAFETY};
use super::solution::{RollingSolution, Verification};
use crate::limits::relaxed;
use crate::quadrature::{Spacing, StripRule};
use crate::similarity::{ExactRatios, Ratios, SimilarityTable};
use crate::spectrum::Terms;
use crate::{ModelError, Quadrature};

/// Solves the rolling contact of `rolling` (docs/model.md §3).
///
/// Fails, never panics nor returns a non-finite number, on parameters outside their ranges,
/// scales beyond double precision, or a root that does not converge.
pub fn solve(rolling: &Rolling, options: &SolveOptions) -> Result<RollingSolution, ModelError> {
    solve_with(rolling, options, None)
}

/// [`solve`], with the load equation solved through `table` (the similarity table of the
/// layer's κ under the same rule) instead of strip sums: the answer then differs from the
/// exact one by at most `verification.table_error`. The contact boundary and the pressure
/// are still the exact strip solutions at the table's penetration.
pub(crate) fn solve_with(
    rolling: &Rolling,
    options: &SolveOptions,
    table: Option<&SimilarityTable>,
) -> Result<RollingSolution, ModelError> {
    ModelError::check_inputs(rolling.violations(), options.violations())?;
    let layer = &rolling.layer;
    let reference = relaxed(rolling.radius, rolling.load, layer);
    let r0 = reference.half_width;
    let xi = rolling.velocity * layer.relaxation_time / r0;
    let viscosity = layer.viscosity(rolling.velocity / r0);
    for (what, value) in [
        ("the static contact half-width √(2Rδ₀)", r0),
        ("V T_σ / r₀", xi),
        ("V τ_j / r₀", viscosity.longest()),
    ] {
        if !value.is_finite() || (value == 0.0 && what == "the static contact half-width √(2Rδ₀)")
        {
            return Err(ModelError::NotRepresentable {
                what: what.to_string(),
            });
        }
    }

    let contact = match table {
        Some(table) if xi > 0.0 => Contact::tabulated(xi, table)?,
        _ => Contact::exact(&viscosity, options.quadrature)?,
    };
    let section = Section::new(contact.half_width, viscosity);
    let half_width = contact.half_width * r0;
    let contact_area = contact.area * r0 * r0;
    let pressure_centre_shift = contact.pressure_centre * r0;
    let solution = RollingSolution {
        penetration: half_width * half_width / (2.0 * rolling.radius),
        contact_area,
        half_width,
        centroid_shift: contact.centroid * r0,
        pressure_centre_shift,
        rolling_resistance_coefficient: pressure_centre_shift / rolling.radius,
        friction_coefficient: layer.interfacial_shear_strength() * contact_area / rolling.load,
        static_contact: reference,
        boundary: section.boundary(options.boundary_points, r0, contact.solved.as_ref())?,
        pressure: match options.pressure_grid {
            Some(n) => Some(section.pressure_grid(n, r0, layer.stiffness() / rolling.radius)?),
            None => None,
        },
        verification: Verification {
            quadrature_nodes: options.quadrature.size(),
            ..contact.verification
        },
    };
    ensure_finite(&solution)?;
    Ok(solution)
}

/// The contact at a given penetration δ rather than a given load (the forward map of the
/// three-body model, docs/model.md §4, and the builder of the similarity tables), as the
/// ratios of the similarity law ([`Ratios`]), which depend only on the viscous terms in units
/// of the half-width √(2Rδ) (for the Kelvin layer ξ = V T_σ/√(2Rδ) and κ,
/// [`crate::Layer::viscosity`]), with the quadrature error estimate a rolling answer would
/// report there, under `quadrature` (its nodes spaced for the shortest term,
/// [`Spacing::for_speed`]). Φ_P runs from 1 (ξ = 0) to 1 + Σκ_j (ξ → ∞); Φ_A is 1 at both
/// ends and dips in between.
pub fn penetration_contact(
    viscosity: &Terms,
    quadrature: Quadrature,
) -> Result<ExactRatios, ModelError> {
    let spacing = Spacing::for_speed(viscosity.shortest());
    let rule = StripRule::shared(quadrature, spacing)?;
    let companion = StripRule::shared(quadrature.companion(), spacing)?;
    let section = Section::new(1.0, *viscosity);
    let mut roots = vec![f64::NAN; rule.len()];
    let integrals = section.integrate(&rule, Some(&mut roots))?;
    // At a given penetration there is no load equation, and so no residual to carry.
    let (moment, error) =
        section.moment_and_error(&rule, &roots, &integrals, &companion, None, 0.0)?;
    let ratios = Ratios {
        load: integrals.load / FRAC_PI_4,
        area: integrals.area / PI,
        centroid: integrals.centroid(),
        pressure_centre: moment / integrals.load,
    };
    Ok((ratios, error))
}

/// Refuses to hand out a non-finite number (serde_json would write it as a silent `null`).
fn ensure_finite(s: &RollingSolution) -> Result<(), ModelError> {
    let verification = [
        s.verification.load_residual,
        s.verification.quadrature_error_estimate,
    ];
    let scalars = s.quantities().into_iter().chain(verification);
    let boundary = s.boundary.iter().flat_map(|p| [p.y, p.exit, p.entry]);
    let pressure = s.pressure.iter().flat_map(|g| {
        g.x.iter()
            .chain(&g.y)
            .chain(g.values.iter().flatten())
            .copied()
    });
    if scalars.chain(boundary).chain(pressure).all(f64::is_finite) {
        Ok(())
    } else {
        Err(ModelError::NotRepresentable {
            what: "a result of this job".to_string(),
        })
    }
}

/// The solved contact in units of r₀ (P̂(r̂) = π/4) and how far to trust it.
struct Contact {
    /// r̂ = √(2Rδ)/r₀ = √(δ/δ₀).
    half_width: f64,
    /// A/r₀².
    area: f64,
    /// x_c/r₀.
    centroid: f64,
    /// x_p/r₀.
    pressure_centre: f64,
    verification: Verification,
    /// The rule solved and its strips' exit roots, if solved by strip sums: a guide for the
    /// boundary's roots.
    solved: Option<(Arc<StripRule>, Vec<f64>)>,
}

impl Contact {
    /// By strip sums: the load root ([`Shape::nested`]), then the pressure moment, then the
    /// same integrals under the companion rule for the quadrature error estimate.
    fn exact(viscosity: &Terms, quadrature: Quadrature) -> Result<Contact, ModelError> {
        let (shape, coarse) = Shape::nested(viscosity, quadrature)?;
        let spacing = Spacing::for_speed(viscosity.shortest());
        let companion = StripRule::shared(quadrature.companion(), spacing)?;
        let section = shape.section(viscosity);
        let (pressure_moment, quadrature_error_estimate) = section.moment_and_error(
            &shape.rule,
            &shape.exit_roots,
            &shape.integrals,
            &companion,
            coarse.map(|coarse| coarse.exit_roots),
            shape.load_residual,
        )?;
        Ok(Contact {
            half_width: shape.half_width,
            area: shape.integrals.area,
            centroid: shape.integrals.centroid(),
            pressure_centre: pressure_moment / shape.integrals.load,
            verification: Verification {
                load_residual: shape.load_residual,
                quadrature_error_estimate,
                quadrature_nodes: shape.rule.len(),
                iterations: shape.iterations,
                exit_root_iterations: shape.integrals.exit_root_iterations,
                converged: true,
                table_error: None,
            },
            solved: Some((shape.rule, shape.exit_roots)),
        })
    }

    /// Through the similarity table: at r̂ the contact is the table's at ξ/r̂ scaled by r̂
    /// (P̂ = (π/4) r̂⁴ Φ_P, Â = π r̂² Φ_A, x/r₀ = r̂ · x/r), so the load equation is
    /// f(t) = 4t + ln Φ_P(ξ e^{−t}) = 0 in t = ln r̂ (nearly linear: f′ lies between 3 and
    /// 4; in r̂ itself the secant needs one or two steps more), solved by the secant method
    /// ([`load_root`]) from t = −¼ ln Φ_P(ξ) and the known f(0) = ln Φ_P(ξ).
    fn tabulated(xi: f64, table: &SimilarityTable) -> Result<Contact, ModelError> {
        let at_rest = table.log_ratios(xi).log_load;
        let root = load_root(
            log_bracket(1.0 + table.kappa()),
            -0.25 * at_rest,
            Some((0.0, at_rest)),
            ELASTIC_SLOPE,
            "penetration (load equation through the similarity table)",
            |t| {
                let ratios = table.log_ratios(xi * (-t).exp());
                Ok((4.0 * t + ratios.log_load, ratios))
            },
        )?;
        let (r, ratios) = (root.t.exp(), root.at);
        let load_residual = root.value.exp_m1().abs();
        Ok(Contact {
            half_width: r,
            area: PI * r * r * ratios.area,
            centroid: r * ratios.centroid,
            pressure_centre: r * ratios.pressure_centre,
            verification: Verification {
                load_residual,
                // The exact solver's bound near ξ (at a given penetration) and what this
                // root leaves, as [`quadrature_error`] carries it.
                quadrature_error_estimate: table.quadrature_error(xi / r)
                    + ERROR_SAFETY * load_residual,
                quadrature_nodes: 0,
                iterations: root.iterations,
                exit_root_iterations: 0,
                converged: true,
                table_error: Some(table.error()),
            },
            solved: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::{FRAC_PI_2, PI};

    use super::*;

    /// The points at θ > 0 are reflections, so they are checked here against their own
    /// strips' exit roots.
    #[test]
    fn the_reflected_half_of_the_boundary_is_that_of_its_own_strips() {
        let rolling = Rolling::default();
        let solution = solve(&rolling, &SolveOptions::default()).unwrap();
        let n = solution.boundary.len();
        let r0 = solution.static_contact.half_width;
        let r = solution.half_width / r0;
        let section = Section::new(r, rolling.layer.viscosity(rolling.velocity / r0));
        for (j, point) in solution.boundary.iter().enumerate().skip(n / 2 + 1) {
            let theta = -FRAC_PI_2 + PI * j as f64 / (n - 1) as f64;
            let strip = section.strip(theta.cos());
            let rho = strip.exit_root(None).unwrap().rho;
            let exit = (rho - 1.0) * strip.entry * r0;
            assert!((point.y / (theta.sin() * r * r0) - 1.0).abs() < 1e-13);
            if j + 1 < n {
                assert!(
                    (point.exit / exit - 1.0).abs() < 1e-12,
                    "{} vs {exit}",
                    point.exit
                );
                assert!((point.entry / (strip.entry * r0) - 1.0).abs() < 1e-13);
            }
        }
    }
}
