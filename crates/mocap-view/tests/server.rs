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
    let mut stream = TcpStream::connect(addr).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    write!(stream, "{method} {path} HTTP/1.0\r\nHost: {host}\r\n\r\n").unwrap();
    let mut response = String::new();
    stream.read_to_string(&mut response).unwrap();
    let status = response[9..12].parse().unwrap();
    let body = response
        .split_once("\r\n\r\n")
        .map(|(_, b)| b.to_string())
        .unwrap_or_default();
    (status, body)
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
