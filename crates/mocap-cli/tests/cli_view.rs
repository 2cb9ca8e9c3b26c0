//! `mocap render` and `mocap view` as a user runs them.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

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

/// A `mocap view` process serving the sample on a free port of 127.0.0.1;
/// killed when dropped.
struct Viewer {
    child: std::process::Child,
    address: String,
}

impl Viewer {
    fn start() -> Viewer {
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
        let address = url["url"]
            .as_str()
            .unwrap()
            .trim_start_matches("http://")
            .trim_end_matches('/')
            .to_string();
        Viewer { child, address }
    }

    fn connect(&self) -> TcpStream {
        let stream = TcpStream::connect(&self.address).unwrap();
        stream
            .set_read_timeout(Some(Duration::from_secs(10)))
            .unwrap();
        stream
            .set_write_timeout(Some(Duration::from_secs(10)))
            .unwrap();
        stream
    }

    /// `GET path` on a connection of its own; the answer's status code, or
    /// what went wrong.
    fn get(&self, path: &str, within: Duration) -> Result<u16, String> {
        let mut stream = TcpStream::connect(&self.address).map_err(|e| e.to_string())?;
        stream.set_read_timeout(Some(within)).unwrap();
        write!(
            stream,
            "GET {path} HTTP/1.1\r\nHost: {}\r\nConnection: close\r\n\r\n",
            self.address
        )
        .map_err(|e| e.to_string())?;
        let mut response = Vec::new();
        stream
            .read_to_end(&mut response)
            .map_err(|e| e.to_string())?;
        let response = String::from_utf8_lossy(&response);
        response
            .strip_prefix("HTTP/1.1 ")
            .and_then(|rest| rest.get(..3))
            .and_then(|code| code.parse().ok())
            .ok_or_else(|| {
                format!(
                    "not an HTTP answer: {:?}",
                    &response[..response.len().min(100)]
                )
            })
    }

    fn is_alive(&mut self) -> bool {
        self.child.try_wait().unwrap().is_none()
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Issue 35, item 1: one request announcing an enormous body killed the
/// viewer (tiny_http allocated the body's length up front).
#[test]
fn view_survives_a_request_announcing_a_huge_body() {
    let mut viewer = Viewer::start();
    let mut stream = viewer.connect();
    write!(
        stream,
        "GET / HTTP/1.1\r\nHost: {}\r\nContent-Length: 99999999999999\r\n\r\nsome",
        viewer.address
    )
    .unwrap();
    let mut refusal = Vec::new();
    let _ = stream.read_to_end(&mut refusal);
    // A chunked body without end is refused as well.
    let mut stream = viewer.connect();
    write!(
        stream,
        "POST /scene.json HTTP/1.1\r\nHost: {}\r\nTransfer-Encoding: chunked\r\n\r\nffffffffffff\r\n",
        viewer.address
    )
    .unwrap();
    let mut response = Vec::new();
    let _ = stream.read_to_end(&mut response);

    assert_eq!(viewer.get("/scene.json", Duration::from_secs(5)), Ok(200));
    assert!(viewer.is_alive(), "the viewer died");
    // The first was refused with 413 and its connection closed (a reset is
    // an answer too).
    let refusal = String::from_utf8_lossy(&refusal);
    assert!(
        refusal.is_empty() || refusal.starts_with("HTTP/1.1 413"),
        "{refusal}"
    );
}

/// Issue 35, item 2: a client that pipelines requests and never reads the
/// answers held the viewer's only thread, and every other client waited.
#[test]
fn view_serves_others_while_a_client_reads_nothing() {
    let mut viewer = Viewer::start();
    let mut greedy = viewer.connect();
    let request = format!(
        "GET /scene.json HTTP/1.1\r\nHost: {}\r\n\r\n",
        viewer.address
    );
    greedy.write_all(request.repeat(200).as_bytes()).unwrap();
    // Let the server fill the socket buffers with answers nobody reads.
    std::thread::sleep(Duration::from_millis(500));

    let start = Instant::now();
    assert_eq!(viewer.get("/", Duration::from_secs(2)), Ok(200));
    assert!(start.elapsed() < Duration::from_secs(2));
    assert_eq!(viewer.get("/scene.json", Duration::from_secs(2)), Ok(200));
    assert!(viewer.is_alive());
    drop(greedy);
}

/// A connection that sends half a request head and stalls is closed after
/// the header timeout (5 s) and holds up nobody meanwhile.
#[test]
fn view_closes_a_stalled_request_head() {
    let viewer = Viewer::start();
    let mut stalled = viewer.connect();
    stalled
        .write_all(b"GET /scene.json HTTP/1.1\r\nHost: 127.0")
        .unwrap();
    let start = Instant::now();
    assert_eq!(viewer.get("/", Duration::from_secs(2)), Ok(200));

    // Closed (perhaps after a 408) well before the 10 s read timeout.
    let mut rest = Vec::new();
    let outcome = stalled.read_to_end(&mut rest);
    let waited = start.elapsed();
    let rest = String::from_utf8_lossy(&rest);
    assert!(
        outcome.is_ok() || waited < Duration::from_secs(9),
        "still open after {waited:?}: {outcome:?}"
    );
    assert!(
        rest.is_empty() || rest.starts_with("HTTP/1.1 408"),
        "{rest}"
    );
    assert!(waited < Duration::from_secs(9), "closed after {waited:?}");
}
