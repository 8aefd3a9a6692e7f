//! Speed of the physics core: one rolling solve at 1e-9 relative accuracy (target: < 100 µs
//! median), through the similarity tables, and a `kelvin_layer` three-body system with a given
//! total load (target: < 20 ms median), and the static continuum contact (the table the
//! local-layer row reads: target < 1 µs), and the same on a layer from a Prony series. The service's own benchmarks (sweeps, figures, the work
//! a request adds, fits) are the service crate's `service` bench. Results and method:
//! BENCHMARKS.md. Run with `cargo bench --bench solver`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use thirdbody_model::continuum;
use thirdbody_model::rolling::penetration_contact;
use thirdbody_model::similarity::SimilarityTable;
use thirdbody_model::spectrum::Terms;
use thirdbody_model::tables::{self, Use};
use thirdbody_model::three_body::{
    self, Asperities, LayerContact, OperatingPoint, ThreeBody, ThreeBodyOptions,
};
use thirdbody_model::Stop;
use thirdbody_model::{solve, Quadrature, Rolling, SolveOptions};

fn rolling(c: &mut Criterion) {
    let mut group = c.benchmark_group("rolling");
    let default = Rolling::default();
    // The default job: V = 4 nm/s, 64 Gauss nodes, 41 boundary points.
    group.bench_function("default_job", |b| {
        b.iter(|| solve(black_box(&default), &SolveOptions::default()).unwrap())
    });
    // As in sweeps: no boundary.
    group.bench_function("integrals_only", |b| {
        let options = SolveOptions::integrals_only(Quadrature::default());
        b.iter(|| solve(black_box(&default), &options).unwrap())
    });
    for velocity in [0.0, 1e-10, 1e-8, 1e-6] {
        let point = Rolling {
            velocity,
            ..default
        };
        let options = SolveOptions::integrals_only(Quadrature::default());
        group.bench_function(format!("integrals_only_V={velocity:e}"), |b| {
            b.iter(|| solve(black_box(&point), &options).unwrap())
        });
    }
    group.bench_function("midpoint_40_strips", |b| {
        let options = SolveOptions::integrals_only(Quadrature::Midpoint { strips: 40 });
        b.iter(|| solve(black_box(&default), &options).unwrap())
    });
    // Through the layer's similarity table, once built (as a sweep's points and a three-body
    // system's sizes are).
    tables::get_or_build(default.layer.kappa(), Quadrature::default()).unwrap();
    group.bench_function("tabulated_default_job", |b| {
        let options = SolveOptions::default();
        b.iter(|| tables::solve(black_box(&default), &options, Use::Build).unwrap())
    });
    group.bench_function("tabulated_integrals_only", |b| {
        let options = SolveOptions::integrals_only(Quadrature::default());
        b.iter(|| tables::solve(black_box(&default), &options, Use::Build).unwrap())
    });
    group.finish();
}

fn three_body(c: &mut Criterion) {
    let mut group = c.benchmark_group("three_body");
    let options = ThreeBodyOptions::default();
    // The default system of docs/model.md §5 carrying W = 1 mN (target: < 20 ms median).
    let kelvin = ThreeBody::with_defaults(OperatingPoint::TotalLoad(1e-3));
    group.bench_function("kelvin_layer_total_load", |b| {
        b.iter(|| three_body::solve(black_box(&kelvin), &options).unwrap())
    });
    group.bench_function("kelvin_layer_separation", |b| {
        let at = ThreeBody {
            operating: OperatingPoint::Separation(58e-9),
            ..kelvin
        };
        b.iter(|| three_body::solve(black_box(&at), &options).unwrap())
    });
    group.bench_function("kelvin_layer_asperities", |b| {
        let rough = ThreeBody {
            asperities: Some(Asperities {
                density: 1e11,
                tip_radius: 1e-6,
                height_std: 5e-9,
                hardness: 1e9,
            }),
            ..kelvin
        };
        b.iter(|| three_body::solve(black_box(&rough), &options).unwrap())
    });
    group.bench_function("hertz_total_load", |b| {
        let hertz = ThreeBody {
            layer_contact: LayerContact::Hertz,
            ..kelvin
        };
        b.iter(|| three_body::solve(black_box(&hertz), &options).unwrap())
    });
    group.bench_function("similarity_table_build", |b| {
        b.iter(|| {
            SimilarityTable::build(black_box(4.0), |xi| {
                penetration_contact(&Terms::one(4.0, xi), Quadrature::default())
            })
            .unwrap()
        })
    });
    group.finish();
}

/// The layer as a continuum at rest (docs/model.md §8): the direct solve on three
/// resolutions, and the table every rolling and three-body answer's local-layer row reads.
fn continuum(c: &mut Criterion) {
    let mut group = c.benchmark_group("continuum");
    let layer = thirdbody_model::Layer::default();
    group.bench_function("static_contact_default", |b| {
        b.iter(|| continuum::static_contact(black_box(25e-9), 1e-9, &layer).unwrap())
    });
    group.bench_function("static_area_table", |b| {
        b.iter(|| continuum::static_area(black_box(25e-9), 1e-9, &layer))
    });
    // The whole continuum answer (three grids: fine, coarse, and a longer wake), at rest
    // and at the default 4 nm/s, and the fine grid's influence alone.
    group.sample_size(10);
    for velocity in [0.0, 4e-9] {
        let point = Rolling {
            velocity,
            ..Rolling::default()
        };
        group.bench_function(format!("answer_V={velocity:e}"), |b| {
            b.iter(|| {
                continuum::solve(black_box(&point), &SolveOptions::default(), Stop::NEVER).unwrap()
            })
        });
    }
    group.finish();
}

/// A layer from a four-term Prony series (docs/model.md §9): a local answer by strip sums
/// (no similarity table serves a series), a three-body system (which tabulates its series
/// once per solve), and a continuum answer (one memory per retardation time).
fn prony(c: &mut Criterion) {
    let mut group = c.benchmark_group("prony");
    let layer = thirdbody_model::Layer::from_prony(
        3e9,
        100e-9,
        0.35,
        &[(6e9, 0.01), (4.5e9, 0.1), (3e9, 1.0), (1.5e9, 10.0)],
    )
    .unwrap();
    let point = Rolling {
        layer,
        ..Rolling::default()
    };
    group.bench_function("local_integrals_only_4_terms", |b| {
        let options = SolveOptions::integrals_only(Quadrature::default());
        b.iter(|| solve(black_box(&point), &options).unwrap())
    });
    group.sample_size(10);
    group.bench_function("three_body_total_load_4_terms", |b| {
        let system = ThreeBody {
            layer,
            ..ThreeBody::with_defaults(OperatingPoint::TotalLoad(1e-3))
        };
        b.iter(|| three_body::solve(black_box(&system), &ThreeBodyOptions::default()).unwrap())
    });
    group.bench_function("continuum_answer_4_terms", |b| {
        b.iter(|| {
            continuum::solve(black_box(&point), &SolveOptions::default(), Stop::NEVER).unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, rolling, three_body, continuum, prony);
criterion_main!(benches);
