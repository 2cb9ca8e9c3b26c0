//! The local web viewer: a page and its script, embedded in the binary, served
//! on the loopback interface together with the scene as JSON.
//!
//! | path | what |
//! | --- | --- |
//! | `/` | the page (`page/index.html`) |
//! | `/viewer.js` | the viewer (`page/viewer.js`): a 2D canvas with a perspective camera |
//! | `/scene.json` | the motions ([`Scene::to_json`], which gives the format) |
//!
//! Nothing is fetched from the network: the page works offline. The server
//! listens on 127.0.0.1 only and answers only requests addressed to a
//! loopback host name, so that a web page elsewhere cannot read the scene
//! through DNS rebinding.

use std::net::{Ipv4Addr, SocketAddr, SocketAddrV4};
use std::sync::Arc;
use std::thread::JoinHandle;

use mocap_core::{Error, Result};
use tiny_http::{Header, Method, Request, Response};

use crate::scene::Scene;

const INDEX_HTML: &str = include_str!("page/index.html");
const VIEWER_JS: &str = include_str!("page/viewer.js");

/// A running viewer server; stops when dropped.
pub struct ViewerServer {
    server: Arc<tiny_http::Server>,
    thread: Option<JoinHandle<()>>,
    addr: SocketAddr,
}

impl ViewerServer {
    /// Starts serving `scene` on `127.0.0.1:port` (port 0 picks a free one)
    /// in a background thread.
    pub fn start(scene: &Scene, port: u16) -> Result<ViewerServer> {
        let wanted = SocketAddr::V4(SocketAddrV4::new(Ipv4Addr::LOCALHOST, port));
        let server = tiny_http::Server::http(wanted).map_err(|e| {
            Error::Invalid(format!(
                "cannot serve the viewer on {wanted}: {e}{}",
                if port != 0 {
                    " (is another program using this port? --port 0 picks a free one)"
                } else {
                    ""
                }
            ))
        })?;
        let addr = server
            .server_addr()
            .to_ip()
            .ok_or_else(|| Error::Invalid("the viewer server has no IP address".to_string()))?;
        let server = Arc::new(server);
        let scene_json = scene.to_json();
        let worker = Arc::clone(&server);
        let thread = std::thread::Builder::new()
            .name("mocap-view http".to_string())
            .spawn(move || {
                for request in worker.incoming_requests() {
                    // A browser that went away mid-answer is no error of ours.
                    let _ = answer(request, &scene_json, addr.port());
                }
            })
            .map_err(|e| Error::Invalid(format!("cannot start the viewer thread: {e}")))?;
        Ok(ViewerServer {
            server,
            thread: Some(thread),
            addr,
        })
    }

    /// The address the server listens on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The page's address, for the user to open.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }

    /// Blocks until the server stops (for `mocap view`, until the process is
    /// interrupted).
    pub fn wait(mut self) {
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }

    /// Stops the server and waits for its thread.
    pub fn stop(self) {
        drop(self)
    }
}

impl Drop for ViewerServer {
    fn drop(&mut self) {
        self.server.unblock();
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// `mocap view`: serves `scene` on `127.0.0.1:port`, prints the address on
/// standard error, and serves until the process is interrupted.
pub fn serve(scene: &Scene, port: u16) -> Result<()> {
    let server = ViewerServer::start(scene, port)?;
    eprintln!(
        "Viewer at {} ({} motion{}); press Ctrl-C to stop.",
        server.url(),
        scene.motions.len(),
        if scene.motions.len() == 1 { "" } else { "s" }
    );
    server.wait();
    Ok(())
}

fn answer(request: Request, scene_json: &str, port: u16) -> std::io::Result<()> {
    if !host_is_loopback(&request, port) {
        return request.respond(text(
            403,
            "the viewer only answers requests to 127.0.0.1 or localhost",
        ));
    }
    if *request.method() != Method::Get && *request.method() != Method::Head {
        return request.respond(text(405, "only GET is supported"));
    }
    let path = request.url().split('?').next().unwrap_or("/");
    let (body, content_type) = match path {
        "/" | "/index.html" => (INDEX_HTML, "text/html; charset=utf-8"),
        "/viewer.js" => (VIEWER_JS, "text/javascript; charset=utf-8"),
        "/scene.json" => (scene_json, "application/json"),
        _ => return request.respond(text(404, "not found")),
    };
    let response = Response::from_string(body)
        .with_header(header("Content-Type", content_type))
        .with_header(header("Cache-Control", "no-store"));
    request.respond(response)
}

/// Whether the `Host` header names a loopback address (or is absent, as with
/// HTTP/1.0 clients).
fn host_is_loopback(request: &Request, port: u16) -> bool {
    let Some(host) = request
        .headers()
        .iter()
        .find(|h| h.field.equiv("Host"))
        .map(|h| h.value.as_str().to_ascii_lowercase())
    else {
        return true;
    };
    ["127.0.0.1", "localhost", "[::1]"]
        .iter()
        .any(|name| host == *name || host == format!("{name}:{port}"))
}

fn text(status: u16, message: &str) -> Response<std::io::Cursor<Vec<u8>>> {
    Response::from_string(message)
        .with_status_code(status)
        .with_header(header("Content-Type", "text/plain; charset=utf-8"))
}

fn header(name: &str, value: &str) -> Header {
    Header::from_bytes(name.as_bytes(), value.as_bytes()).expect("ASCII header names and values")
}
