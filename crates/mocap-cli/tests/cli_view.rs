//! `mocap render` and `mocap view` as a user runs them.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Command, Stdio};

fn sample() -> String {
    mocap_testdata::sample_walk().display().to_string()
}

#[test]
fn render_writes_a_filmstrip_png() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("strip.png");
    let out = Command::new(env!("CARGO_BIN_EXE_mocap"))
        .args([
            "render",
            &sample(),
            "-o",
            png.to_str().unwrap(),
            "--frames",
            "0..60",
            "--every",
            "20",
            "--json",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(summary["frames"], serde_json::json!([0, 20, 40]));
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
}

#[test]
fn view_serves_the_page_on_loopback() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_mocap"))
        .args(["view", &sample(), "--port", "0", "--json"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut first_line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first_line)
        .unwrap();
    let url: serde_json::Value = serde_json::from_str(&first_line).unwrap();
    let url = url["url"].as_str().unwrap().to_string();
    let address = url.trim_start_matches("http://").trim_end_matches('/');
    assert!(address.starts_with("127.0.0.1:"), "{url}");
    let mut stream = TcpStream::connect(address).unwrap();
    write!(
        stream,
        "GET / HTTP/1.1\r\nHost: {address}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut response = String::new();
    stream.read_to_string(&mut response).unwrap();
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        response.starts_with("HTTP/1.1 200"),
        "{}",
        &response[..response.len().min(200)]
    );
    assert!(response.contains("<canvas"), "the page has no canvas");
}
