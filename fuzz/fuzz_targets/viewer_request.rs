//! Any bytes sent to the web viewer as one connection's requests get well-formed
//! answers or none, never a panic, and the connection ends once the client
//! has sent everything and closed its side (on a paused clock, so the
//! server's timeouts pass at once).
#![no_main]

use std::time::Duration;

use libfuzzer_sys::fuzz_target;
use tokio::io::{AsyncReadExt, AsyncWriteExt};

const SCENE_JSON: &str = r#"{"motions":[]}"#;
const PORT: u16 = 8080;

thread_local! {
    static RUNTIME: tokio::runtime::Runtime = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .start_paused(true)
        .build()
        .expect("a runtime");
}

fuzz_target!(|data: &[u8]| {
    let answer = RUNTIME.with(|runtime| runtime.block_on(exchange(data)));
    let answer = answer.expect("the connection outlived every timeout of the server");
    assert!(
        answer.is_empty() || answer.starts_with(b"HTTP/1."),
        "not an HTTP answer: {:?}",
        String::from_utf8_lossy(&answer[..answer.len().min(200)])
    );
});

/// Sends `data` then closes the client's side, reading the answers all the
/// while; `None` if the server has not closed within a virtual hour.
async fn exchange(data: &[u8]) -> Option<Vec<u8>> {
    let (client, server) = tokio::io::duplex(64 * 1024);
    let (mut from_server, mut to_server) = tokio::io::split(client);
    let send = async {
        // The server may close first: what it did not read is its business.
        let _ = to_server.write_all(data).await;
        let _ = to_server.shutdown().await;
    };
    let receive = async {
        let mut answer = Vec::new();
        let _ = from_server.read_to_end(&mut answer).await;
        answer
    };
    let serve = mocap_view::serve_connection(server, SCENE_JSON, PORT);
    let everything = async {
        let ((), (), answer) = tokio::join!(serve, send, receive);
        answer
    };
    tokio::time::timeout(Duration::from_secs(3600), everything)
        .await
        .ok()
}
