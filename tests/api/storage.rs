//! The storage seams: two services whose engines share one store of answers and jobs see
//! each other's work, as replicas behind a shared backend will.

use serde_json::json;
use thirdbody::engine::Storage;
use thirdbody::http::AppState;

use crate::helpers::{config, serve};

#[tokio::test]
async fn services_sharing_a_storage_share_answers_and_jobs() {
    let config = config(&[]);
    let storage = Storage::in_process(&config.engine).expect("the database opens");
    let a = serve(AppState::with_storage(config.clone(), storage.clone())).await;
    let b = serve(AppState::with_storage(config, storage)).await;

    let solved = a.post("/v1/rolling", &json!({"load": "1.3 nN"})).await;
    assert_eq!(solved.headers()["x-cache"], "miss");
    let again = b.post("/v1/rolling", &json!({"load": "1.3 nN"})).await;
    assert_eq!(again.headers()["x-cache"], "hit");
    assert_eq!(b.solves(&[]).await, 0.0);

    let location = a
        .submit(&json!({"kind": "sweep", "input": {"vary": {"load": ["1 nN", "1.1 nN"]}}}))
        .await;
    let job = b
        .wait_for_job(&location, |j| j["status"] == "succeeded")
        .await;
    assert_eq!(job["progress"], json!({"done": 2, "total": 2}));
    assert_eq!(b.result(&job).await["points"].as_array().unwrap().len(), 2);
}
