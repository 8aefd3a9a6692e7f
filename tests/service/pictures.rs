//! Every answer has a picture: SVG that parses, with axes, one path per series and a legend
//! naming each, drawn from the answer's own numbers; Figures 3 and 6 are snapshot-tested
//! (`UPDATE_SNAPSHOTS=1 cargo test --test service pictures` rewrites them after a deliberate change).

use serde_json::{json, Value};
use thirdbody::job::figure::FigurePicture;
use thirdbody::job::fit::FitPicture;
use thirdbody::job::picture::shown;
use thirdbody::job::rolling::RollingPicture;
use thirdbody::job::sweep::SweepPicture;
use thirdbody::job::three_body::ThreeBodyPicture;
use thirdbody::job::{Control, Job, Limits};
use thirdbody::render::svg::Chart;
use thirdbody::render::svg::{Layer, HEATMAP_CELLS};
use thirdbody::render::Format;
use thirdbody::render::{draw, Picture};

/// The answer to `job` as JSON and as SVG.
fn solve(job: Value) -> (Value, String) {
    let job = Job::from_value(job, &Limits::default()).unwrap();
    let answer = job.run(job.meta(), &Control::default()).unwrap();
    let json = serde_json::from_slice(&answer.render(Format::Json).unwrap()).unwrap();
    let svg = String::from_utf8(answer.render(Format::Svg).unwrap()).unwrap();
    (json, svg)
}

/// The chart a kind's picture `P` draws of `answer`.
fn chart<P: Picture>(answer: &Value) -> Chart {
    draw::<P>(&serde_json::to_vec(answer).unwrap()).unwrap()
}

/// Checks the SVG's structure; returns the names of its series and its legend entries.
fn parts(svg: &str) -> (Vec<String>, Vec<String>) {
    let doc = roxmltree::Document::parse(svg).expect("the picture is XML");
    let root = doc.root_element();
    assert_eq!(root.tag_name().name(), "svg");
    assert_eq!(root.attribute("width"), Some("800"));
    assert_eq!(root.attribute("height"), Some("500"));
    let class = |node: &roxmltree::Node, name: &str| {
        node.attribute("class")
            .is_some_and(|c| c.split(' ').any(|c| c == name))
    };
    for axis in ["x", "y"] {
        let found = doc
            .descendants()
            .find(|n| class(n, "axis") && class(n, axis))
            .unwrap_or_else(|| panic!("no {axis} axis"));
        let label = found.descendants().find(|n| class(n, "label")).unwrap();
        assert!(
            !label.text().unwrap_or("").is_empty(),
            "the {axis} axis has a label"
        );
        assert!(
            found.children().filter(|n| n.has_tag_name("text")).count() >= 3,
            "ticks"
        );
    }
    assert!(doc.descendants().any(|n| class(&n, "title")));
    let series = doc
        .descendants()
        .filter(|n| class(n, "series"))
        .map(|n| n.attribute("data-name").unwrap_or("").to_string())
        .collect();
    let legend = doc
        .descendants()
        .filter(|n| class(n, "entry"))
        .map(|n| n.text().unwrap_or("").to_string())
        .collect();
    (series, legend)
}

#[test]
fn a_rolling_contact_is_its_contact_region_at_its_size() {
    let (answer, svg) = solve(json!({"kind": "rolling", "input": {}}));
    let (series, legend) = parts(&svg);
    assert_eq!(
        series,
        [
            "contact, V = 4 nm/s",
            "at rest, V = 0",
            "pressure centre",
            "centroid"
        ]
    );
    assert_eq!(legend, series);
    let chart = chart::<RollingPicture>(&answer);
    let Layer::Area { outline, .. } = &chart.layers[0] else {
        panic!("the contact region comes first");
    };
    let half_width = answer["half_width"].as_f64().unwrap();
    let extent = outline.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
    assert!(
        (extent - half_width).abs() <= 1e-12 * half_width,
        "{extent} vs {half_width}"
    );
    let leading = outline.iter().map(|p| p.0).fold(f64::MIN, f64::max);
    let edge = answer["boundary"].as_array().unwrap().iter();
    let entry = edge
        .map(|p| p["entry"].as_f64().unwrap())
        .fold(f64::MIN, f64::max);
    assert_eq!(leading, entry);
    let Layer::Circle { radius, .. } = &chart.layers[1] else {
        panic!("then the contact at rest");
    };
    let at_rest = answer["static"]["contact_area"].as_f64().unwrap();
    assert!((std::f64::consts::PI * radius * radius / at_rest - 1.0).abs() < 1e-12);
}

#[test]
fn a_pressure_grid_is_a_heat_map_with_a_colour_bar() {
    let (_, svg) = solve(json!({"kind": "rolling", "input": {"options": {"pressure_grid": 20}}}));
    parts(&svg);
    assert!(svg.contains(r#"<g class="colourbar">"#));
    assert!(svg.contains("pressure [MPa]"));
    // Drawn inside the contact's outline only: no cell sticks out past its edge.
    let doc = roxmltree::Document::parse(&svg).unwrap();
    let heatmap = doc
        .descendants()
        .find(|n| n.attribute("class") == Some("heatmap"))
        .unwrap();
    assert_eq!(heatmap.attribute("clip-path"), Some("url(#heatmap-clip)"));
    let clip = doc
        .descendants()
        .find(|n| n.attribute("id") == Some("heatmap-clip"))
        .unwrap();
    let outline = doc
        .descendants()
        .find(|n| n.attribute("data-name") == Some("contact, V = 4 nm/s"))
        .unwrap();
    let clip_path = clip.first_element_child().unwrap().attribute("d");
    assert_eq!(clip_path, outline.attribute("d"));
}

#[test]
fn a_one_point_sweep_draws_its_point() {
    let (_, svg) = solve(json!({"kind": "sweep", "input": {"vary": {"load": ["1 nN"]}}}));
    parts(&svg);
    assert_eq!(svg.matches(r#"<circle class="lone""#).count(), 1, "{svg}");
}

#[test]
fn more_lines_than_the_palette_has_run_along_a_sequential_map_in_their_order() {
    let loads: Vec<String> = (1..=12)
        .map(|i| format!("{} nN", f64::from(i) * 0.25))
        .collect();
    // Along the speed (the longer list), a line per load.
    let speeds: Vec<String> = (0..14).map(|v| format!("{v} nm/s")).collect();
    let (_, svg) = solve(json!({"kind": "sweep", "input": {"vary": {
        "load": loads, "velocity": speeds}}}));
    let (series, _) = parts(&svg);
    assert_eq!(
        series.len(),
        12 + 1,
        "a line per load, and the points at rest"
    );
    let stroke = |name: &str| {
        let at = svg.find(&format!(r#"data-name="{name}""#)).unwrap();
        let rest = &svg[at..];
        let start = rest.find("stroke=\"").unwrap() + 8;
        rest[start..start + 7].to_string()
    };
    // viridis from its dark end towards its light one, in the order of the loads: its green
    // grows all along it.
    assert_eq!(stroke("P = 0.25 nN"), "#440154");
    let names = &series[..12];
    let greens: Vec<u8> = names
        .iter()
        .map(|name| u8::from_str_radix(&stroke(name)[3..5], 16).unwrap())
        .collect();
    assert!(
        greens.windows(2).all(|w| w[0] < w[1]),
        "{names:?}: {greens:?}"
    );
}

#[test]
fn the_finest_pressure_grid_draws_a_picture_of_bounded_size_that_says_so() {
    let grid = 501; // the largest the options allow
    let (answer, svg) =
        solve(json!({"kind": "rolling", "input": {"options": {"pressure_grid": grid}}}));
    parts(&svg);
    assert_eq!(answer["pressure"]["values"].as_array().unwrap().len(), grid);
    let cells = svg.matches("<rect ").count();
    assert!(
        cells <= HEATMAP_CELLS * HEATMAP_CELLS + 40,
        "{cells} rectangles"
    );
    // A 71-byte request drew 12.1 MB when every value had its cell.
    assert!(svg.len() < 1 << 20, "{} bytes", svg.len());
    assert!(svg.contains("pressure drawn on 100 × 100 cells"));
    assert!(svg.contains("(the answer has 501 × 501)"));
}

#[test]
fn a_sweep_has_a_curve_per_other_value_and_marks_points_at_rest() {
    let (answer, svg) = solve(json!({"kind": "sweep", "input": {"vary": {
        "load": ["0.5 nN", "1 nN", "2 nN"], "velocity": ["0 nm/s", "2 nm/s", "4 nm/s"]}}}));
    let (series, legend) = parts(&svg);
    assert_eq!(
        series,
        ["P = 0.5 nN", "P = 1 nN", "P = 2 nN", "at rest, V = 0"]
    );
    assert_eq!(legend, series);
    // One condition, one unit in the legend: its largest value's (issue 52: "P = 500 pN"
    // beside "P = 2 nN", "V = 0 m/s" beside "V = 4 nm/s").
    let (_, at_rest) = solve(json!({"kind": "sweep", "input": {"vary": {
        "load": ["0.5 nN", "1 nN", "2 nN"], "velocity": ["0 nm/s", "4 nm/s"]}}}));
    let (series, _) = parts(&at_rest);
    assert_eq!(series, ["V = 0 nm/s", "V = 4 nm/s", "at rest, V = 0"]);
    // Which law of the layer answered is said (issue 52), and on the continuum its error.
    assert!(svg.contains("layer: local law (the paper's)"), "{svg}");
    let (solved, continuum) = solve(json!({"kind": "sweep", "input": {
        "base": {"layer": {"model": "continuum"}}, "vary": {"load": ["0.5 nN", "1 nN"]}}}));
    let error = solved["meta"]["verification"]["contact_area_error"]
        .as_f64()
        .unwrap();
    let said = format!("layer: continuum, A within ±{:.2} %", 100.0 * error);
    assert!(continuum.contains(&said), "{said}: {continuum}");
    let chart = chart::<SweepPicture>(&answer);
    let Layer::Line { points, .. } = &chart.layers[1] else {
        panic!()
    };
    let rows: Vec<&Value> = answer["points"].as_array().unwrap()[3..6].iter().collect();
    for (p, row) in points.iter().zip(rows) {
        assert_eq!(p.0, row["velocity"].as_f64().unwrap());
        assert_eq!(p.1, row["friction_coefficient"].as_f64().unwrap());
    }
    assert_eq!(chart.x.quantity, "velocity");
    assert!(svg.contains("velocity [nm/s]"));
}

#[test]
fn a_sweep_draws_the_points_it_answered_and_counts_those_it_did_not() {
    let (_, svg) = solve(json!({"kind": "sweep", "input": {"vary": {
        "load": ["1 nN", "1 mN", "2 nN"]}}}));
    let (series, _) = parts(&svg);
    assert_eq!(series, ["sweep"]);
    let doc = roxmltree::Document::parse(&svg).unwrap();
    let notes: Vec<&str> = doc
        .descendants()
        .filter(|n| n.attribute("class") == Some("notes"))
        .flat_map(|n| n.children().filter_map(|t| t.text()))
        .collect();
    assert_eq!(
        notes,
        [
            "layer: local law (the paper's)",
            "1 of 3 points not drawn:",
            "refused, or not solved"
        ]
    );
}

/// The particles in contact shaded by how they move (docs/model.md §11): at 1 mN the
/// smallest roll, the middle ones slide against the steel, the largest on the layer, each
/// population between the separation and the diameters where the mode changes.
#[test]
fn a_three_body_system_shades_the_particles_in_contact_and_splits_the_area() {
    let (answer, svg) = solve(json!({"kind": "three_body",
        "input": {"operating": {"total_load": "1 mN"}}}));
    let (series, _) = parts(&svg);
    assert_eq!(
        series[..4],
        [
            "diameters",
            "in contact: rolls",
            "in contact: slides on upper",
            "in contact: slides on layer"
        ]
    );
    let chart = chart::<ThreeBodyPicture>(&answer);
    let separation = answer["separation"].as_f64().unwrap();
    let changes: Vec<f64> = answer["motion"]["changes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["diameter"].as_f64().unwrap())
        .collect();
    let edges: Vec<f64> = [separation]
        .into_iter()
        .chain(changes)
        .chain([65e-9])
        .collect();
    for (i, piece) in edges.windows(2).enumerate() {
        let Layer::Area { outline, .. } = &chart.layers[1 + i] else {
            panic!()
        };
        let (lo, hi) = (piece[0], piece[1]);
        assert!(
            outline.iter().all(|p| lo <= p.0 && p.0 <= hi),
            "{lo:e}..{hi:e}"
        );
        assert_eq!(outline.first().unwrap().0, lo);
        assert_eq!(outline.last().unwrap().0, hi);
    }
    assert!(svg.contains("35,600 roll, 18,900 slide"), "{svg}");
    assert!(svg.contains("particle diameter [nm]") && svg.contains("particle–upper: 100.0 %"));
    // The count as a person reads it, not 5.4450e4.
    assert!(
        svg.contains("<title>Three-body system: 54,500 particles in contact</title>"),
        "{svg}"
    );
}

#[test]
fn a_fit_draws_each_series_measured_and_fitted_with_its_residuals() {
    let text = include_str!("../../examples/fit.json");
    let (answer, svg) = solve(serde_json::from_str(text).unwrap());
    let (series, legend) = parts(&svg);
    assert_eq!(
        legend,
        [
            "R = 25 nm, P = 800 pN, measured",
            "R = 25 nm, P = 800 pN, fitted",
            "R = 25 nm, P = 1.2 nN, measured",
            "R = 25 nm, P = 1.2 nN, fitted"
        ]
    );
    // Per series: its markers, its curve; per point its residual and its error bar.
    assert_eq!(series.len(), 2 * 2 + 2 * 30);
    let chart = chart::<FitPicture>(&answer);
    let Layer::Line { points, .. } = &chart.layers[1] else {
        panic!("the fitted curve")
    };
    let curve = answer["curves"][0]["points"].as_array().unwrap();
    assert_eq!(points.len(), curve.len());
    assert_eq!(
        points[0].1,
        curve[0]["friction_coefficient"].as_f64().unwrap()
    );
    let Layer::Line { points, dashed, .. } = &chart.layers[2] else {
        panic!("a residual")
    };
    let first = &answer["residuals"][0]["friction_coefficient"];
    assert!(*dashed);
    assert_eq!(points[0].1, first["measured"].as_f64().unwrap());
    assert_eq!(points[1].1, first["fitted"].as_f64().unwrap());
    // Its error bar: ± the uncertainty given, solid.
    let Layer::Line { points, dashed, .. } = &chart.layers[3] else {
        panic!("an error bar")
    };
    let (measured, uncertainty) = (
        first["measured"].as_f64().unwrap(),
        first["uncertainty"].as_f64().unwrap(),
    );
    assert!(!*dashed);
    assert_eq!(points[0].1, measured - uncertainty);
    assert_eq!(points[1].1, measured + uncertainty);
    // The fitted values with their intervals, as the answer has them.
    let modulus = &answer["parameters"]["elastic_modulus"];
    let [lo, hi] = [0, 1].map(|i| modulus["interval_95"][i].as_f64().unwrap());
    let value = format!("E_L = {}", shown(modulus["value"].as_f64().unwrap(), "Pa"));
    let note = format!("95 %: {} to {}", shown(lo, "Pa"), shown(hi, "Pa"));
    assert!(svg.contains(&format!(">{value}<")), "{value} in {svg}");
    assert!(svg.contains(&note), "{note} in {svg}");
}

#[test]
fn each_figure_draws_every_series_of_its_answer() {
    for number in 3..=9 {
        let (answer, svg) = solve(json!({"kind": "figure", "input": {"number": number}}));
        let (series, legend) = parts(&svg);
        let expected = answer["series"].as_array().unwrap();
        assert_eq!(series.len(), expected.len(), "Fig. {number}");
        assert_eq!(legend.len(), expected.len(), "Fig. {number}");
        for (label, name) in expected.iter().zip(&legend) {
            assert!(
                label["label"].as_str().unwrap().ends_with(name.as_str()),
                "Fig. {number}"
            );
        }
        let chart = chart::<FigurePicture>(&answer);
        for (layer, curve) in chart.layers.iter().zip(expected) {
            let Layer::Line { points, dashed, .. } = layer else {
                panic!()
            };
            let data: Vec<(f64, f64)> = curve["points"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
                .collect();
            assert_eq!(points, &data, "Fig. {number}");
            assert_eq!(
                *dashed,
                curve["velocity"] == 0.0,
                "Fig. {number}: at rest dashed"
            );
        }
    }
}

#[test]
fn figures_3_and_6_match_their_snapshots() {
    for number in [3, 6] {
        let (_, svg) = solve(json!({"kind": "figure", "input": {"number": number}}));
        let path = format!(
            "{}/tests/snapshots/figure-{number}.svg",
            env!("CARGO_MANIFEST_DIR")
        );
        if std::env::var_os("UPDATE_SNAPSHOTS").is_some() {
            std::fs::write(&path, &svg).unwrap();
        }
        let snapshot = std::fs::read_to_string(&path).expect("the snapshot is committed");
        assert!(svg == snapshot, "Fig. {number} differs from {path}");
    }
}
