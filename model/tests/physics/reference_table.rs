//! docs/model.md §3 reference table, to every printed digit.

use thirdbody_model::{solve, Layer, Rolling, SolveOptions};

/// One row: R nm, P nN, V nm/s, δ nm, a(0) nm, b(0) nm, A nm², x_c nm, x_p nm, μ; and the
/// number of decimals printed for each of δ, a, b, A, x_c, x_p, μ.
type Row = (f64, f64, f64, [f64; 7], [i32; 7]);

// One row a line, as the table in docs/model.md prints it.
#[rustfmt::skip]
const TABLE: [Row; 6] = [
    (25.0, 1.0, 0.0, [0.6515, -5.7073, 5.7073, 102.333, 0.0, 0.0, 0.11370], [4, 4, 4, 3, 0, 0, 5]),
    (25.0, 1.0, 2.0, [0.6433, -4.9553, 5.6713, 93.367, 0.3477, 0.6602, 0.10374], [4, 4, 4, 3, 4, 4, 5]),
    (25.0, 1.0, 4.0, [0.6237, -4.3180, 5.5842, 85.234, 0.5970, 1.0692, 0.09470], [4, 4, 4, 3, 4, 4, 5]),
    (25.0, 1.0, 10.0, [0.5470, -3.1651, 5.2297, 68.474, 0.9002, 1.3948, 0.07608], [4, 4, 4, 3, 4, 4, 5]),
    (150.0, 1.0, 4.0, [0.2607, -7.4588, 8.8443, 222.898, 0.6673, 1.2469, 0.24766], [4, 4, 4, 3, 4, 4, 5]),
    (350.0, 1.4, 4.0, [0.2037, -10.4994, 11.9397, 415.254, 0.7004, 1.3337, 0.32957], [4, 4, 4, 3, 4, 4, 5]),
];

#[test]
fn solver_reproduces_the_reference_table_to_every_printed_digit() {
    let options = SolveOptions {
        boundary_points: 3, // y = −r, 0, r: the middle one is the centre strip
        ..SolveOptions::default()
    };
    for (radius, load, velocity, expected, decimals) in TABLE {
        let rolling = Rolling {
            radius: radius * 1e-9,
            load: load * 1e-9,
            velocity: velocity * 1e-9,
            layer: Layer::default(),
        };
        let s = solve(&rolling, &options).unwrap();
        let centre = s.boundary[1];
        assert_eq!(centre.y, 0.0);
        let computed = [
            s.penetration * 1e9,
            centre.exit * 1e9,
            centre.entry * 1e9,
            s.contact_area * 1e18,
            s.centroid_shift * 1e9,
            s.pressure_centre_shift * 1e9,
            s.friction_coefficient,
        ];
        let names = ["δ", "a(0)", "b(0)", "A", "x_c", "x_p", "μ"];
        for k in 0..7 {
            let half_unit = 0.5 * 10f64.powi(-decimals[k]);
            assert!(
                (computed[k] - expected[k]).abs() <= half_unit * (1.0 + 1e-9),
                "R = {radius} nm, P = {load} nN, V = {velocity} nm/s: {} = {} but the table \
                 prints {}",
                names[k],
                computed[k],
                expected[k]
            );
        }
    }
}
