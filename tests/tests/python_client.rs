//! A Python client (eclipse-zenoh 1.10.2 + msgpack, installed by tests/run.sh) subscribes to a
//! live fleet's intents and traffic constraints and decodes them using nothing but
//! schemas/README.md: on a plain fleet, and on a secured one (`demo --secure`) with its own
//! observer credentials.

use gapfleet_tests::{binary, free_endpoint};
use std::process::{Command, Stdio};
use std::time::Duration;

/// The Python with the client's packages: $GAPFLEET_PYTHON (tests/run.sh sets it) or python3.
fn python() -> String {
    std::env::var("GAPFLEET_PYTHON").unwrap_or_else(|_| "python3".to_owned())
}

/// The Python, checked for the client's packages.
fn checked_python() -> String {
    let python = python();
    let check = Command::new(&python)
        .args(["-c", "import zenoh, msgpack"])
        .status()
        .expect("python runs");
    assert!(
        check.success(),
        "{python} lacks eclipse-zenoh/msgpack: run `bash tests/run.sh` (it installs them) or set GAPFLEET_PYTHON"
    );
    python
}

/// The client's JSON summary, once it succeeded with 40 intents from several robots.
fn client_summary(out: &std::process::Output, fleet: &str) -> serde_json::Value {
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "client failed: {}\n{stdout}",
        String::from_utf8_lossy(&out.stderr)
    );
    println!("python client ({fleet} fleet): {stdout}");
    let summary: serde_json::Value = serde_json::from_str(stdout.trim()).expect("JSON summary");
    assert_eq!(summary["received"], 40, "{summary}");
    assert!(
        summary["robots"].as_array().is_some_and(|r| r.len() >= 2),
        "intents from several robots: {summary}"
    );
    summary
}

const CLIENT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/python/intent_client.py");

#[test]
fn python_client_decodes_a_live_fleets_intents() {
    let python = checked_python();
    let endpoint = free_endpoint();
    let mut demo = Command::new(binary("gapfleet"))
        .args(["demo", "--robots", "4", "--humans", "10", "--seconds", "60"])
        .args(["--speed", "2", "--site", "pytest", "--listen", &endpoint])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("gapfleet demo starts");
    // Wait until the coordinator's router accepts connections.
    let addr = endpoint.trim_start_matches("tcp/");
    gapfleet_tests::wait_until(Duration::from_secs(30), || {
        std::net::TcpStream::connect(addr).ok()
    })
    .unwrap_or_else(|| panic!("the demo never listened on {addr}"));
    let out = Command::new(&python)
        .args([CLIENT, "--connect", &endpoint, "--site", "pytest"])
        .args(["--count", "40", "--timeout", "30"])
        .output()
        .expect("the client runs");
    let _ = demo.kill();
    let _ = demo.wait();
    let summary = client_summary(&out, "plain");
    // The fleet's planner, `pnp-right`, announces the path it chose.
    assert_eq!(summary["planners"], serde_json::json!(["pnp-right"]));
    assert_eq!(
        summary["max_samples"], 6,
        "pnp-right's 1.5 s horizon at 4 Hz: {summary}"
    );
    assert!(summary["map_obstacles"].as_u64().is_some_and(|n| n > 4));
    // The traffic policy runs by default: every robot's constraint arrives beside its
    // observation, and robots driving along the 3 m corridors are asked to keep right.
    assert!(
        summary["traffic_received"].as_u64().is_some_and(|n| n > 0),
        "{summary}"
    );
    let kinds = summary["traffic_constraints"].as_array().expect("a list");
    assert!(kinds.contains(&serde_json::json!("lane")), "{summary}");
}

/// The same client on a secured fleet: it connects with the site's `observer-python`
/// credentials (mutual TLS, user and password), reads intents and the map, and the run's
/// summary is that of the plain fleet.
#[test]
fn python_client_reads_a_secured_fleet_with_its_own_credentials() {
    use std::io::BufRead;
    let python = checked_python();
    let mut demo = Command::new(binary("gapfleet"))
        .args(["demo", "--robots", "4", "--humans", "10", "--seconds", "60"])
        .args(["--speed", "2", "--site", "pysec", "--secure"])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("gapfleet demo starts");
    // The demo names its site's folder on stderr; the rest of stderr is drained meanwhile.
    let stderr = demo.stderr.take().expect("piped");
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in std::io::BufReader::new(stderr)
            .lines()
            .map_while(Result::ok)
        {
            if let Some(dir) = line.split("site files in ").nth(1) {
                let _ = tx.send(dir.trim().to_owned());
            }
        }
    });
    let dir = rx
        .recv_timeout(Duration::from_secs(30))
        .expect("the secured demo names its site folder");
    let config = format!("{dir}/observer-python/zenoh.json5");
    let out = Command::new(&python)
        .args([CLIENT, "--config", &config, "--site", "pysec"])
        .args(["--count", "40", "--timeout", "30"])
        .output()
        .expect("the client runs");
    // SIGTERM: the demo shuts down and removes its site folder.
    let _ = Command::new("kill")
        .args(["-TERM", &demo.id().to_string()])
        .status();
    let _ = demo.wait();
    assert!(
        !std::path::Path::new(&dir).exists(),
        "the demo removed its site folder {dir}"
    );
    let summary = client_summary(&out, "secured");
    assert!(summary["map_obstacles"].as_u64().is_some_and(|n| n > 4));
}
