//! The deployment files, checked offline (no cluster, no Docker engine here; `.ci/run` also
//! validates every resource against Kubernetes' schemas): every file the kustomization
//! names parses, and the invariants between them hold: probes on the service's own
//! endpoints, a preStop drain within the grace period, resources, the image set by the
//! kustomization, the Redis URLs pointing at the Redis Services with the password of the
//! Secret each Redis asks for, the job store on a claim, Redis reachable from the API's pods
//! alone, the autoscaler and the disruption budget on the Deployment; the compose file
//! builds with the commit and runs two replicas, a worker, Redis and Prometheus scraping
//! all three.

use std::path::Path;

use serde_yaml::Value;

fn read(path: &str) -> Vec<Value> {
    let full = Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    let text = std::fs::read_to_string(&full).unwrap_or_else(|e| panic!("{path}: {e}"));
    serde_yaml::Deserializer::from_str(&text)
        .map(|d| serde::Deserialize::deserialize(d).unwrap_or_else(|e| panic!("{path}: {e}")))
        .collect()
}

fn one(path: &str) -> Value {
    read(path).remove(0)
}

fn find<'a>(docs: &'a [Value], kind: &str) -> &'a Value {
    docs.iter()
        .find(|d| d["kind"] == kind)
        .unwrap_or_else(|| panic!("no {kind}"))
}

/// A YAML list of strings.
fn strings(list: &Value) -> Vec<&str> {
    list.as_sequence()
        .unwrap()
        .iter()
        .map(|a| a.as_str().unwrap())
        .collect()
}

#[test]
fn the_kustomize_base_wires_probes_drain_redis_autoscaler_and_budget() {
    let kustomization = one("deploy/base/kustomization.yaml");
    let mut docs = Vec::new();
    for resource in kustomization["resources"].as_sequence().unwrap() {
        docs.extend(read(&format!("deploy/base/{}", resource.as_str().unwrap())));
    }
    let deployments: Vec<&Value> = docs.iter().filter(|d| d["kind"] == "Deployment").collect();
    let app = deployments
        .iter()
        .find(|d| d["metadata"]["name"] == "thirdbody")
        .unwrap();
    let pod = &app["spec"]["template"]["spec"];
    let container = &pod["containers"][0];
    assert_eq!(container["readinessProbe"]["httpGet"]["path"], "/readyz");
    assert_eq!(container["livenessProbe"]["httpGet"]["path"], "/healthz");
    for bound in ["requests", "limits"] {
        assert!(
            container["resources"][bound]["cpu"].is_string(),
            "{bound} cpu"
        );
    }
    // The memory the pod is given holds its budget and what the process needs besides
    // (measured: 93 MiB at most, reliability/pod_memory.py), and the limit is above it.
    let mebibytes = |bound: &str| -> u64 {
        let text = container["resources"][bound]["memory"].as_str().unwrap();
        text.strip_suffix("Mi").unwrap().parse().unwrap()
    };
    let literals = strings(&kustomization["configMapGenerator"][0]["literals"]);
    let budget: u64 = literals
        .iter()
        .find_map(|l| l.strip_prefix("THIRDBODY_MEMORY_BUDGET="))
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        mebibytes("requests") >= (budget >> 20) + 100,
        "a request of {} MiB for a budget of {} MiB",
        mebibytes("requests"),
        budget >> 20
    );
    assert!(mebibytes("limits") > mebibytes("requests"));
    let pre_stop = &container["lifecycle"]["preStop"]["exec"]["command"];
    assert_eq!(pre_stop[0], "sleep");
    let sleep: u64 = pre_stop[1].as_str().unwrap().parse().unwrap();
    // The image's THIRDBODY_SHUTDOWN_TIMEOUT (25 s) after the preStop sleep.
    let grace = pod["terminationGracePeriodSeconds"].as_u64().unwrap();
    assert!(grace > sleep + 25, "grace {grace} s");

    // The configuration reaches the pods; the image is the kustomization's to set.
    let config = &kustomization["configMapGenerator"][0];
    assert_eq!(
        container["envFrom"][0]["configMapRef"]["name"],
        config["name"]
    );
    assert_eq!(container["image"], "thirdbody");
    let image = &kustomization["images"][0];
    assert_eq!(image["name"], "thirdbody");
    assert!(
        image["newName"].as_str().unwrap().contains('/'),
        "a registry"
    );
    assert!(image["newTag"].is_string());

    // Each Redis asks for the password of one Secret, which the API's URLs carry.
    let secret = |env: &Value, name: &str| -> String {
        let var = env
            .as_sequence()
            .unwrap()
            .iter()
            .find(|v| v["name"] == name)
            .unwrap_or_else(|| panic!("{name} is set"));
        let from = &var["valueFrom"]["secretKeyRef"];
        format!(
            "{}/{}",
            from["name"].as_str().unwrap(),
            from["key"].as_str().unwrap()
        )
    };
    let password = secret(&container["env"], "REDIS_PASSWORD");
    let url_of = |variable: &str| -> String {
        container["env"]
            .as_sequence()
            .unwrap()
            .iter()
            .find(|v| v["name"] == variable)
            .and_then(|v| v["value"].as_str())
            .unwrap_or_else(|| panic!("{variable} is configured"))
            .to_string()
    };
    // Two Redis roles, each its own Service and server: the cache may evict, the jobs
    // never are evicted and are persisted on a claim.
    for (variable, name, kind, policy, persisted) in [
        (
            "THIRDBODY_REDIS_URL",
            "thirdbody-redis-cache",
            "Deployment",
            "allkeys-lru",
            "no",
        ),
        (
            "THIRDBODY_REDIS_JOBS_URL",
            "thirdbody-redis-jobs",
            "StatefulSet",
            "noeviction",
            "yes",
        ),
    ] {
        let service = docs
            .iter()
            .find(|d| d["kind"] == "Service" && d["metadata"]["name"] == name)
            .unwrap_or_else(|| panic!("no Service {name}"));
        let port = service["spec"]["ports"][0]["port"].as_u64().unwrap();
        assert_eq!(
            url_of(variable),
            format!("redis://:$(REDIS_PASSWORD)@{name}:{port}")
        );
        let redis = docs
            .iter()
            .find(|d| d["kind"] == kind && d["metadata"]["name"] == name)
            .unwrap_or_else(|| panic!("no {kind} {name}"));
        assert_eq!(
            service["spec"]["selector"],
            redis["spec"]["selector"]["matchLabels"]
        );
        let server = &redis["spec"]["template"]["spec"]["containers"][0];
        let args = strings(&server["args"]);
        assert!(
            args.windows(2).any(|w| w == ["--maxmemory-policy", policy]),
            "{name}"
        );
        assert!(
            args.windows(2).any(|w| w == ["--appendonly", persisted]),
            "{name}"
        );
        assert!(
            args.windows(2)
                .any(|w| w == ["--requirepass", "$(REDIS_PASSWORD)"]),
            "{name} asks for a password"
        );
        for variable in ["REDIS_PASSWORD", "REDISCLI_AUTH"] {
            assert_eq!(
                secret(&server["env"], variable),
                password,
                "{name} {variable}"
            );
        }
        if persisted == "yes" {
            let mount = &server["volumeMounts"][0];
            assert_eq!(mount["mountPath"], "/data");
            let claim = &redis["spec"]["volumeClaimTemplates"][0];
            assert_eq!(
                claim["metadata"]["name"], mount["name"],
                "{name}: /data on a claim"
            );
        }
        // Only the API's pods reach it.
        let policy = find(&docs, "NetworkPolicy");
        let selected = policy["spec"]["podSelector"]["matchExpressions"][0]["values"]
            .as_sequence()
            .unwrap();
        assert!(selected.iter().any(|v| v == name), "{name} is guarded");
        let from = &policy["spec"]["ingress"][0];
        assert_eq!(
            from["from"][0]["podSelector"]["matchLabels"],
            app["spec"]["selector"]["matchLabels"]
        );
        assert_eq!(from["ports"][0]["port"].as_u64(), Some(port));
    }

    // The autoscaler and the budget act on the API's Deployment.
    let hpa = find(&docs, "HorizontalPodAutoscaler");
    assert_eq!(hpa["spec"]["scaleTargetRef"]["name"], "thirdbody");
    assert_eq!(hpa["spec"]["metrics"][0]["resource"]["name"], "cpu");
    let pdb = find(&docs, "PodDisruptionBudget");
    assert_eq!(
        pdb["spec"]["selector"]["matchLabels"],
        app["spec"]["selector"]["matchLabels"]
    );
    let service = docs
        .iter()
        .find(|d| d["kind"] == "Service" && d["metadata"]["name"] == "thirdbody")
        .unwrap();
    assert_eq!(
        service["spec"]["selector"],
        app["spec"]["selector"]["matchLabels"]
    );
}

#[test]
fn compose_runs_two_replicas_a_worker_two_redis_roles_and_prometheus_scraping_all_three() {
    let compose = one("deploy/compose.yaml");
    let services = compose["services"].as_mapping().unwrap();
    let get = |name: &str| &services[&Value::from(name)];
    let anchor = &compose["x-thirdbody"];
    // The image names the commit it was built from (the Dockerfile's build argument).
    let commit = "THIRDBODY_GIT_COMMIT";
    assert_eq!(
        anchor["build"]["args"][commit],
        format!("${{{commit}:-unknown}}").as_str()
    );
    let dockerfile = std::fs::read_to_string("Dockerfile").unwrap();
    assert!(dockerfile.contains(&format!("ARG {commit}")));
    // The cache may evict; the jobs never are evicted, and are persisted.
    for (variable, name, policy, persisted) in [
        ("THIRDBODY_REDIS_URL", "redis-cache", "allkeys-lru", "no"),
        (
            "THIRDBODY_REDIS_JOBS_URL",
            "redis-jobs",
            "noeviction",
            "yes",
        ),
    ] {
        assert_eq!(
            anchor["environment"][variable],
            format!("redis://{name}:6379").as_str()
        );
        let command = strings(&get(name)["command"]);
        assert!(
            command
                .windows(2)
                .any(|w| w == ["--maxmemory-policy", policy]),
            "{name}"
        );
        assert!(
            command.windows(2).any(|w| w == ["--appendonly", persisted]),
            "{name}"
        );
    }
    for replica in ["thirdbody-a", "thirdbody-b"] {
        assert!(get(replica)["ports"][0]
            .as_str()
            .unwrap()
            .ends_with(":8080"));
    }
    let worker = get("worker");
    assert_eq!(worker["command"][0], "worker");
    // The worker serves its metrics on a port of its own, its health check asks there.
    let bind = worker["environment"]["THIRDBODY_METRICS_BIND"]
        .as_str()
        .unwrap();
    assert_eq!(bind, "0.0.0.0:9100");
    assert_eq!(
        strings(&worker["healthcheck"]["test"])[1..],
        ["thirdbody", "healthcheck", "--bind", "127.0.0.1:9100"]
    );
    let prometheus = one("deploy/prometheus.yml");
    let targets = &prometheus["scrape_configs"][0]["static_configs"][0]["targets"];
    assert_eq!(targets[0], "thirdbody-a:8080");
    assert_eq!(targets[1], "thirdbody-b:8080");
    assert_eq!(targets[2], "worker:9100");
    assert_eq!(prometheus["scrape_configs"][0]["metrics_path"], "/metrics");
}
