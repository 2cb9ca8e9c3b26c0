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
//! through DNS rebinding. Only `GET` and `HEAD` are answered (405 otherwise),
//! and no answer may be cached.
//!
//! The server is hyper's HTTP/1 connection on a tokio runtime of one thread,
//! each connection a task of its own, so that a client that never reads its
//! answers holds up nobody else. What one client can cost is bounded:
//!
//! - request bodies are never read (`GET` and `HEAD` have none): a request
//!   that announces one over [`MAX_BODY_BYTES`], or one of unknown length
//!   (chunked), is answered 413 and its connection closed;
//! - a request head may hold at most [`MAX_HEADER_BYTES`] (431 beyond);
//! - a request head must arrive within [`HEADER_TIMEOUT`], which is also how
//!   long an idle keep-alive connection stays open;
//! - an answer that makes no progress for [`WRITE_STALL_TIMEOUT`] (a client
//!   that does not read) closes its connection, and no connection lives longer
//!   than [`CONNECTION_LIFETIME`];
//! - at most [`MAX_CONNECTIONS`] connections are served at once; further ones
//!   wait in the listening socket's queue until one closes.

use std::convert::Infallible;
use std::future::Future;
use std::io;
use std::net::{Ipv4Addr, SocketAddr, SocketAddrV4};
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};
use std::thread::JoinHandle;
use std::time::Duration;

use bytes::Bytes;
use http_body_util::Full;
use hyper::body::{Body, Incoming};
use hyper::header::{HeaderValue, CACHE_CONTROL, CONNECTION, CONTENT_TYPE, HOST};
use hyper::{Method, Request, Response, StatusCode};
use hyper_util::rt::{TokioIo, TokioTimer};
use mocap_core::{Error, Result};
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::sync::{oneshot, Semaphore};
use tokio::time::Sleep;

use crate::scene::Scene;

const INDEX_HTML: &str = include_str!("page/index.html");
const VIEWER_JS: &str = include_str!("page/viewer.js");

/// Connections served at once; more wait until one closes.
const MAX_CONNECTIONS: usize = 64;
/// The largest request head (request line and headers), in bytes.
const MAX_HEADER_BYTES: usize = 16 * 1024;
/// The largest request body announced that is not refused with 413. Bodies
/// are never read.
const MAX_BODY_BYTES: u64 = 1024;
/// Time for a request head to arrive, and for an idle connection to send its
/// next request.
const HEADER_TIMEOUT: Duration = Duration::from_secs(5);
/// Time an answer may wait for the client to read before the connection is
/// closed.
const WRITE_STALL_TIMEOUT: Duration = Duration::from_secs(10);
/// The longest a connection is served.
const CONNECTION_LIFETIME: Duration = Duration::from_secs(300);

/// What the server serves: the scene's JSON and the port it listens on (for
/// the `Host` check).
struct Site {
    scene_json: Bytes,
    port: u16,
}

/// A running viewer server; stops when dropped.
pub struct ViewerServer {
    stop: Option<oneshot::Sender<()>>,
    thread: Option<JoinHandle<()>>,
    addr: SocketAddr,
}

impl ViewerServer {
    /// Starts serving `scene` on `127.0.0.1:port` (port 0 picks a free one)
    /// in a background thread.
    pub fn start(scene: &Scene, port: u16) -> Result<ViewerServer> {
        let wanted = SocketAddr::V4(SocketAddrV4::new(Ipv4Addr::LOCALHOST, port));
        let listener = std::net::TcpListener::bind(wanted).map_err(|e| {
            Error::Invalid(format!(
                "cannot serve the viewer on {wanted}: {e}{}",
                if port != 0 {
                    " (is another program using this port? --port 0 picks a free one)"
                } else {
                    ""
                }
            ))
        })?;
        let addr = listener
            .local_addr()
            .map_err(|e| Error::Invalid(format!("the viewer server has no address: {e}")))?;
        listener
            .set_nonblocking(true)
            .map_err(|e| Error::Invalid(format!("cannot serve the viewer on {addr}: {e}")))?;
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_io()
            .enable_time()
            .build()
            .map_err(|e| Error::Invalid(format!("cannot start the viewer's runtime: {e}")))?;
        let site = Arc::new(Site {
            scene_json: Bytes::from(scene.to_json()),
            port: addr.port(),
        });
        let (stop, stopped) = oneshot::channel();
        let thread = std::thread::Builder::new()
            .name("mocap-view http".to_string())
            .spawn(move || {
                runtime.block_on(accept_loop(listener, site, stopped));
                // Dropping the runtime ends every connection still open.
                drop(runtime);
            })
            .map_err(|e| Error::Invalid(format!("cannot start the viewer thread: {e}")))?;
        Ok(ViewerServer {
            stop: Some(stop),
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
        if let Some(stop) = self.stop.take() {
            let _ = stop.send(());
        }
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

/// Accepts connections until `stopped` fires, each served on a task of its
/// own while it holds one of [`MAX_CONNECTIONS`] permits.
async fn accept_loop(
    listener: std::net::TcpListener,
    site: Arc<Site>,
    mut stopped: oneshot::Receiver<()>,
) {
    let Ok(listener) = tokio::net::TcpListener::from_std(listener) else {
        return;
    };
    let permits = Arc::new(Semaphore::new(MAX_CONNECTIONS));
    loop {
        let permit = tokio::select! {
            _ = &mut stopped => return,
            permit = Arc::clone(&permits).acquire_owned() => match permit {
                Ok(permit) => permit,
                Err(_) => return,
            },
        };
        let stream = tokio::select! {
            _ = &mut stopped => return,
            accepted = listener.accept() => match accepted {
                Ok((stream, _)) => stream,
                // Out of file descriptors, or a connection reset before we
                // took it: wait a little rather than spin.
                Err(_) => {
                    tokio::time::sleep(Duration::from_millis(50)).await;
                    continue;
                }
            },
        };
        let _ = stream.set_nodelay(true);
        let site = Arc::clone(&site);
        tokio::spawn(async move {
            serve_io(stream, site).await;
            drop(permit);
        });
    }
}

/// Serves the viewer over one connection of any byte stream, `scene_json`
/// as `/scene.json`, checking `Host` against `port`; returns when the
/// connection ends. For the fuzz target `viewer_request`, which drives it
/// over an in-memory pipe; it runs on a tokio runtime with time enabled.
#[doc(hidden)]
pub async fn serve_connection<IO>(io: IO, scene_json: &str, port: u16)
where
    IO: AsyncRead + AsyncWrite + Unpin,
{
    let site = Arc::new(Site {
        scene_json: Bytes::copy_from_slice(scene_json.as_bytes()),
        port,
    });
    serve_io(io, site).await
}

async fn serve_io<IO>(io: IO, site: Arc<Site>)
where
    IO: AsyncRead + AsyncWrite + Unpin,
{
    let io = TokioIo::new(StallGuard::new(io, WRITE_STALL_TIMEOUT));
    let service = hyper::service::service_fn(move |request| {
        let site = Arc::clone(&site);
        async move { Ok::<_, Infallible>(answer(&request, &site)) }
    });
    let connection = hyper::server::conn::http1::Builder::new()
        .timer(TokioTimer::new())
        .header_read_timeout(HEADER_TIMEOUT)
        .max_header_size(MAX_HEADER_BYTES)
        .max_buf_size(MAX_HEADER_BYTES.max(8192))
        // A client may shut its side down after sending its request and
        // still wait for the answer.
        .half_close(true)
        .serve_connection(io, service);
    // A client that went away mid-answer, or sent garbage, is no error of
    // ours: hyper has answered what could be answered.
    let _ = tokio::time::timeout(CONNECTION_LIFETIME, connection).await;
}

/// The answer to one request. Its body, if any, is never read.
fn answer(request: &Request<Incoming>, site: &Site) -> Response<Full<Bytes>> {
    if !host_is_loopback(request, site.port) {
        return text(
            StatusCode::FORBIDDEN,
            "the viewer only answers requests to 127.0.0.1 or localhost",
        );
    }
    let body = request.body();
    if !body.is_end_stream()
        && body
            .size_hint()
            .upper()
            .is_none_or(|length| length > MAX_BODY_BYTES)
    {
        let mut response = text(
            StatusCode::PAYLOAD_TOO_LARGE,
            "the viewer reads no request bodies",
        );
        response
            .headers_mut()
            .insert(CONNECTION, HeaderValue::from_static("close"));
        return response;
    }
    if request.method() != Method::GET && request.method() != Method::HEAD {
        let mut response = text(
            StatusCode::METHOD_NOT_ALLOWED,
            "only GET and HEAD are supported",
        );
        response
            .headers_mut()
            .insert("allow", HeaderValue::from_static("GET, HEAD"));
        return response;
    }
    let (body, content_type) = match request.uri().path() {
        "/" | "/index.html" => (
            Bytes::from_static(INDEX_HTML.as_bytes()),
            "text/html; charset=utf-8",
        ),
        "/viewer.js" => (
            Bytes::from_static(VIEWER_JS.as_bytes()),
            "text/javascript; charset=utf-8",
        ),
        "/scene.json" => (site.scene_json.clone(), "application/json"),
        _ => return text(StatusCode::NOT_FOUND, "not found"),
    };
    // For HEAD, hyper sends the length and leaves the body out.
    response(StatusCode::OK, body, content_type)
}

/// Whether the request is addressed to a loopback host: its `Host` header
/// (absent with HTTP/1.0 clients) and the authority of an absolute URI, if
/// any, must name one.
fn host_is_loopback(request: &Request<Incoming>, port: u16) -> bool {
    if let Some(authority) = request.uri().authority() {
        if !is_loopback_name(authority.as_str(), port) {
            return false;
        }
    }
    let mut hosts = request.headers().get_all(HOST).iter();
    match (hosts.next(), hosts.next()) {
        (None, _) => true,
        (Some(host), None) => host.to_str().is_ok_and(|host| is_loopback_name(host, port)),
        // Two Host headers: which one would a proxy have believed?
        (Some(_), Some(_)) => false,
    }
}

fn is_loopback_name(host: &str, port: u16) -> bool {
    let host = host.to_ascii_lowercase();
    ["127.0.0.1", "localhost", "[::1]"]
        .iter()
        .any(|name| host == *name || host == format!("{name}:{port}"))
}

fn text(status: StatusCode, message: &'static str) -> Response<Full<Bytes>> {
    response(
        status,
        Bytes::from_static(message.as_bytes()),
        "text/plain; charset=utf-8",
    )
}

fn response(status: StatusCode, body: Bytes, content_type: &'static str) -> Response<Full<Bytes>> {
    let mut response = Response::new(Full::new(body));
    *response.status_mut() = status;
    let headers = response.headers_mut();
    headers.insert(CONTENT_TYPE, HeaderValue::from_static(content_type));
    headers.insert(CACHE_CONTROL, HeaderValue::from_static("no-store"));
    response
}

/// A byte stream whose writes fail with `TimedOut` once one has been pending
/// (the client reads nothing) for longer than `limit`.
struct StallGuard<IO> {
    io: IO,
    limit: Duration,
    stalled_since: Option<Pin<Box<Sleep>>>,
}

impl<IO> StallGuard<IO> {
    fn new(io: IO, limit: Duration) -> StallGuard<IO> {
        StallGuard {
            io,
            limit,
            stalled_since: None,
        }
    }

    /// Passes on a write's outcome, arming the stall timer while it is
    /// pending and disarming it on progress.
    fn watch<T>(
        &mut self,
        cx: &mut Context<'_>,
        outcome: Poll<io::Result<T>>,
    ) -> Poll<io::Result<T>> {
        if outcome.is_ready() {
            self.stalled_since = None;
            return outcome;
        }
        let limit = self.limit;
        let timer = self
            .stalled_since
            .get_or_insert_with(|| Box::pin(tokio::time::sleep(limit)));
        match timer.as_mut().poll(cx) {
            Poll::Ready(()) => Poll::Ready(Err(io::Error::new(
                io::ErrorKind::TimedOut,
                "the client reads nothing",
            ))),
            Poll::Pending => Poll::Pending,
        }
    }
}

impl<IO: AsyncRead + Unpin> AsyncRead for StallGuard<IO> {
    fn poll_read(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &mut ReadBuf<'_>,
    ) -> Poll<io::Result<()>> {
        Pin::new(&mut self.io).poll_read(cx, buf)
    }
}

impl<IO: AsyncWrite + Unpin> AsyncWrite for StallGuard<IO> {
    fn poll_write(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &[u8],
    ) -> Poll<io::Result<usize>> {
        let outcome = Pin::new(&mut self.io).poll_write(cx, buf);
        self.watch(cx, outcome)
    }

    fn poll_write_vectored(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        bufs: &[io::IoSlice<'_>],
    ) -> Poll<io::Result<usize>> {
        let outcome = Pin::new(&mut self.io).poll_write_vectored(cx, bufs);
        self.watch(cx, outcome)
    }

    fn is_write_vectored(&self) -> bool {
        self.io.is_write_vectored()
    }

    fn poll_flush(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        let outcome = Pin::new(&mut self.io).poll_flush(cx);
        self.watch(cx, outcome)
    }

    fn poll_shutdown(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        let outcome = Pin::new(&mut self.io).poll_shutdown(cx);
        self.watch(cx, outcome)
    }
}
