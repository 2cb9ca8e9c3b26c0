//! The viewer server: what it serves, to whom, and that it stops.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::Path;
use std::time::Duration;

use mocap_view::{Scene, ViewerServer};

fn sample_scene() -> Scene {
    let sample =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/dataset-1_walk_normal_001.bvh");
    Scene::from_files(&[sample]).unwrap()
}

/// One HTTP/1.0 request (no chunked answer to decode); returns the status
/// code and the body.
fn request(addr: SocketAddr, method: &str, path: &str, host: &str) -> (u16, String) {
    let (status, _, body) = exchange(
        addr,
        &format!("{method} {path} HTTP/1.0\r\nHost: {host}\r\n\r\n"),
    );
    (status, body)
}

/// Sends `request` as it is and reads the answer to the end: the status
/// code, the head and the body.
fn exchange(addr: SocketAddr, request: &str) -> (u16, String, String) {
    let mut stream = TcpStream::connect(addr).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    stream.write_all(request.as_bytes()).unwrap();
    let mut response = String::new();
    stream.read_to_string(&mut response).unwrap();
    assert!(response.starts_with("HTTP/1."), "{response}");
    let status = response[9..12].parse().unwrap();
    let (head, body) = response.split_once("\r\n\r\n").unwrap_or((&response, ""));
    (status, head.to_ascii_lowercase(), body.to_string())
}

#[test]
fn serves_the_page_its_script_and_the_scene_on_loopback() {
    let scene = sample_scene();
    let server = ViewerServer::start(&scene, 0).unwrap();
    let addr = server.addr();
    assert!(addr.ip().is_loopback());
    assert_eq!(server.url(), format!("http://{addr}/"));
    let host = addr.to_string();

    let (status, page) = request(addr, "GET", "/", &host);
    assert_eq!(status, 200);
    assert!(page.contains("<canvas id=\"view\""));
    assert!(page.contains("<script src=\"viewer.js\">"));
    // No network at run time: nothing is loaded from another host.
    assert!(!page.contains("http://") && !page.contains("https://"));

    let (status, script) = request(addr, "GET", "/viewer.js", &host);
    assert_eq!(status, 200);
    assert!(script.contains("window.mocapViewer"));
    assert!(!script.contains("http://") && !script.contains("https://"));

    let (status, json) = request(addr, "GET", "/scene.json?x=1", "localhost");
    assert_eq!(status, 200);
    let json: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(
        json["motions"][0]["frame_count"],
        scene.motions[0].frame_count
    );

    assert_eq!(request(addr, "GET", "/secrets", &host).0, 404);
    assert_eq!(request(addr, "POST", "/scene.json", &host).0, 405);
    // A page on another site reaching us by DNS rebinding is refused.
    assert_eq!(
        request(addr, "GET", "/scene.json", "attacker.example:80").0,
        403
    );

    server.stop();
    // The listening socket closes as the server thread winds down: allow it
    // up to two seconds.
    let deadline = std::time::Instant::now() + Duration::from_secs(2);
    while TcpStream::connect_timeout(&addr, Duration::from_millis(200)).is_ok() {
        assert!(
            std::time::Instant::now() < deadline,
            "still listening 2 s after stop"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}

#[test]
fn head_gives_the_length_and_bodies_are_refused_unread() {
    let scene = sample_scene();
    let server = ViewerServer::start(&scene, 0).unwrap();
    let addr = server.addr();
    let close = "Connection: close\r\n";

    let (status, head, body) = exchange(
        addr,
        &format!("HEAD /scene.json HTTP/1.1\r\nHost: {addr}\r\n{close}\r\n"),
    );
    assert_eq!(status, 200);
    assert!(head.contains(&format!("content-length: {}", scene.to_json().len())));
    assert!(head.contains("cache-control: no-store"));
    assert!(body.is_empty());

    // A body announced too large to be anything but an attack, or of unknown
    // length, is refused before a byte of it is read.
    let (status, head, _) = exchange(
        addr,
        &format!("GET / HTTP/1.1\r\nHost: {addr}\r\nContent-Length: 99999999999999\r\n\r\n"),
    );
    assert_eq!(status, 413);
    assert!(head.contains("connection: close"));
    let (status, _, _) = exchange(
        addr,
        &format!("POST / HTTP/1.1\r\nHost: {addr}\r\nTransfer-Encoding: chunked\r\n\r\n5\r\nhello"),
    );
    assert_eq!(status, 413);
    // A short one is left unread and the request answered.
    let (status, _, _) = exchange(
        addr,
        &format!("GET / HTTP/1.1\r\nHost: {addr}\r\nContent-Length: 2\r\n{close}\r\nhi"),
    );
    assert_eq!(status, 200);

    // An absolute URI names the host too.
    let (status, _, _) = exchange(
        addr,
        &format!("GET http://attacker.example/scene.json HTTP/1.1\r\nHost: {addr}\r\n{close}\r\n"),
    );
    assert_eq!(status, 403);
    let (status, head, _) = exchange(
        addr,
        &format!("DELETE / HTTP/1.1\r\nHost: {addr}\r\n{close}\r\n"),
    );
    assert_eq!(status, 405);
    assert!(head.contains("allow: get, head"));
    // An enormous head is refused.
    let (status, _, _) = exchange(
        addr,
        &format!(
            "GET / HTTP/1.1\r\nHost: {addr}\r\nX-Pad: {}\r\n\r\n",
            "a".repeat(100_000)
        ),
    );
    assert_eq!(status, 431);
}

#[test]
fn a_busy_port_is_a_clear_error() {
    let scene = sample_scene();
    let first = ViewerServer::start(&scene, 0).unwrap();
    let port = first.addr().port();
    let error = ViewerServer::start(&scene, port)
        .err()
        .expect("the port is taken")
        .to_string();
    assert!(error.contains(&format!("127.0.0.1:{port}")), "{error}");
    assert!(error.contains("--port 0"), "{error}");
}
