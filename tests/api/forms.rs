//! Every answer in the form the client accepts: JSON or CSV for every job's answer, one
//! form for the other resources, and 406 with a problem when none is acceptable.

use reqwest::Method;
use serde_json::{json, Value};

use crate::helpers::{problem, problem_type, spawn_app};

#[tokio::test]
async fn every_job_answer_comes_as_csv_when_asked() {
    let app = spawn_app(&[]).await;
    let csv = [("accept", "text/csv")];
    for (path, body, first) in [
        (
            "/v1/rolling",
            json!({}),
            "radius [m],load [N],velocity [m/s],penetration [m]",
        ),
        (
            "/v1/three-body",
            json!({"operating": {"total_load": "1 mN"}}),
            "total_load [N],velocity [m/s],mean_diameter [m],separation [m]",
        ),
    ] {
        let response = app.post_with(path, &csv, &body).await;
        assert_eq!(response.status(), 200, "{path}");
        assert!(response.headers()["etag"]
            .to_str()
            .unwrap()
            .ends_with(".csv\""));
        let text = response.text().await.unwrap();
        assert!(text.starts_with(first), "{text}");
        assert_eq!(text.lines().count(), 2, "{text}");
    }
    // The CSV row holds the same numbers as the JSON answer.
    let json: Value = app.post_json("/v1/rolling", &json!({})).await;
    let text = app
        .post_with("/v1/rolling", &csv, &json!({}))
        .await
        .text()
        .await
        .unwrap();
    let row: Vec<f64> = text
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .map_while(|c| c.parse().ok())
        .collect();
    assert_eq!(row[4], json["contact_area"].as_f64().unwrap());
    assert_eq!(row[9], json["friction_coefficient"].as_f64().unwrap());
    // The bound of A's error is the continuum's column (issue 47): empty on the local law,
    // whose quadrature error bounds every row alike.
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let column = header.iter().position(|h| *h == "contact_area_error");
    let cell = text.lines().nth(1).unwrap().split(',').nth(column.unwrap());
    assert_eq!(cell, Some(""));
    let continuum = json!({"layer": {"model": "continuum"}});
    let csv_text = app
        .post_with("/v1/rolling", &csv, &continuum)
        .await
        .text()
        .await
        .unwrap();
    let json: Value = app.post_json("/v1/rolling", &continuum).await;
    let cell = csv_text
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .nth(column.unwrap());
    let bound = &json["meta"]["verification"]["contact_area_error"];
    assert_eq!(cell.unwrap().parse::<f64>().ok(), bound.as_f64());
}

#[tokio::test]
async fn a_form_no_resource_offers_is_406_before_any_work() {
    let app = spawn_app(&[]).await;
    let png = [("accept", "image/png")];
    let refused = app.get_with("/v1/figures/6", &png).await;
    let refusal = problem(refused, 406).await;
    assert_eq!(refusal["type"], problem_type("not-acceptable"));
    assert!(refusal["detail"].as_str().unwrap().contains("text/csv"));
    assert_eq!(app.solves(&[]).await, 0.0, "nothing was solved");

    let csv = [("accept", "text/csv")];
    let body = json!({"kind": "rolling"});
    for (method, path, body, accept) in [
        (Method::POST, "/v1/rolling", Some(&body), &png),
        (Method::POST, "/v1/jobs", Some(&body), &csv),
        (Method::GET, "/healthz", None, &csv),
        (Method::GET, "/readyz", None, &png),
        (
            Method::GET,
            "/metrics",
            None,
            &[("accept", "application/json")],
        ),
    ] {
        let response = app.send(method.clone(), path, accept, body).await;
        problem(response, 406).await;
    }
    let location = app.submit(&body).await;
    problem(app.get_with(&location, &csv).await, 406).await;
    let events = format!("{location}/events");
    problem(app.get_with(&events, &csv).await, 406).await;

    // Wildcards and browsers' lists are served.
    for accept in [
        "*/*",
        "application/*",
        "text/html,application/xhtml+xml,*/*;q=0.8",
    ] {
        let response = app.get_with("/healthz", &[("accept", accept)]).await;
        assert_eq!(response.status(), 200, "{accept}");
    }
}
