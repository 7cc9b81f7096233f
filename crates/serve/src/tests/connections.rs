//! The real server over loopback: the accept loop's bounds under floods of idle and slow
//! connections, its timeouts, and a bounded load test.

use crate::router;

/// Opens `count` connections to `address` that send nothing.
async fn idle_connections(
    address: std::net::SocketAddr,
    count: usize,
) -> Vec<tokio::net::TcpStream> {
    let mut idle = Vec::with_capacity(count);
    for _ in 0..count {
        idle.push(
            tokio::net::TcpStream::connect(address)
                .await
                .expect("connect (the test needs 2 descriptors per idle connection)"),
        );
    }
    idle
}

/// One real request on a fresh connection, answered within a second.
async fn answered_within_a_second(address: std::net::SocketAddr) -> String {
    use tokio::io::{AsyncReadExt, AsyncWriteExt};
    let request = async {
        let mut fresh = tokio::net::TcpStream::connect(address)
            .await
            .expect("connect");
        let head = format!("GET /api/models HTTP/1.1\r\nHost: {address}\r\n\r\n");
        fresh.write_all(head.as_bytes()).await.expect("send");
        let mut response = Vec::new();
        fresh.read_to_end(&mut response).await.expect("read");
        String::from_utf8_lossy(&response).into_owned()
    };
    tokio::time::timeout(std::time::Duration::from_secs(1), request)
        .await
        .expect("a request is answered within a second")
}

/// 2,000 idle connections and slow headers held open by another program do not stop a real
/// request: it is answered within a second, with every flooding connection still open.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn a_request_is_answered_under_two_thousand_idle_connections() {
    use tokio::io::AsyncWriteExt;
    let address = spawn_server().await;
    assert!(
        crate::max_waiting() >= 2_100,
        "this test needs a descriptor limit of at least 4,200 (ulimit -n), which lets 2,100 \
            connections wait; {} may wait here",
        crate::max_waiting()
    );
    let idle = idle_connections(address, 2_000).await;
    let mut slow = Vec::new();
    for _ in 0..50 {
        let mut stream = tokio::net::TcpStream::connect(address)
            .await
            .expect("connect");
        stream
            .write_all(b"GET / HTTP/1.1\r\nHost: loc")
            .await
            .expect("send");
        slow.push(stream);
    }
    let answer = answered_within_a_second(address).await;
    assert!(answer.starts_with("HTTP/1.1 200"), "{answer}");
    drop((idle, slow));
}

/// Beyond the waiting bound the oldest waiting connection is closed to make room: a flood
/// far larger than the bound costs the bound, and a request is still answered.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn beyond_the_bound_the_oldest_waiting_connection_is_closed() {
    use tokio::io::AsyncReadExt;
    let address = spawn_server_with(64).await;
    let mut idle = idle_connections(address, 2_000).await;
    let answer = answered_within_a_second(address).await;
    assert!(answer.starts_with("HTTP/1.1 200"), "{answer}");
    // The first connections were closed by the server at once (not after the idle timeout),
    // the last 64 are still open.
    let mut buffer = [0_u8; 16];
    let first = tokio::time::timeout(std::time::Duration::from_secs(1), idle[0].read(&mut buffer))
        .await
        .expect("the oldest connection was closed");
    assert!(matches!(first, Ok(0) | Err(_)), "{first:?}");
    let last = idle.last_mut().expect("connections");
    assert!(
        tokio::time::timeout(
            std::time::Duration::from_millis(200),
            last.read(&mut buffer)
        )
        .await
        .is_err(),
        "the newest waiting connection is still open"
    );
}

/// Idle connections and slow headers are closed after their timeouts.
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn idle_connections_and_slow_headers_are_timed_out() {
    use tokio::io::{AsyncReadExt, AsyncWriteExt};
    let address = spawn_server().await;
    let mut idle = idle_connections(address, 16).await;
    let mut slow = tokio::net::TcpStream::connect(address)
        .await
        .expect("connect");
    slow.write_all(b"GET / HTTP/1.1\r\nHost: loc")
        .await
        .expect("send");
    let limit = crate::IDLE_TIMEOUT.max(crate::HEADER_TIMEOUT) + std::time::Duration::from_secs(5);
    let mut buffer = [0_u8; 64];
    let closed = tokio::time::timeout(limit, idle[0].read(&mut buffer))
        .await
        .expect("the idle connection is closed in time");
    assert!(matches!(closed, Ok(0) | Err(_)), "{closed:?}");
    // hyper may answer 408 or just close: either ends the read in time.
    let _ = tokio::time::timeout(limit, slow.read(&mut buffer))
        .await
        .expect("the slow header is cut off in time");
}

/// The real server (accept loop and all) on a free loopback port, until the test ends.
pub(super) async fn spawn_server() -> std::net::SocketAddr {
    spawn_server_with(crate::max_waiting()).await
}

/// [`spawn_server`] with at most `most_waiting` connections waiting for their request.
async fn spawn_server_with(most_waiting: usize) -> std::net::SocketAddr {
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0")
        .await
        .expect("bind");
    let address = listener.local_addr().expect("address");
    tokio::spawn(crate::listen::serve_with(
        listener,
        router(),
        std::future::pending(),
        most_waiting,
    ));
    address
}

/// The resident set size of this process, in KiB (Linux), if it can be read.
fn resident_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|line| line.starts_with("VmRSS:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// A bounded load test over loopback: the real server, 400 requests 40 at a time on fresh
/// connections (renders among them), within a fixed time; no error, and memory that stays
/// bounded (renders are capped at two at a time, so requests queue instead of piling up).
#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn loopback_load_test_has_no_error_and_bounded_memory() {
    use tokio::io::{AsyncReadExt, AsyncWriteExt};
    let address = spawn_server().await;
    let before = resident_kib();
    let request = |k: usize| async move {
        let path = match k % 4 {
            0 => format!("/api/render?object=teapot&size=128&n={}", 1 + k % 997),
            1 => format!("/api/evaluate?lobe=logexp&n={}", 1 + k % 997),
            2 => format!("/api/analyze?lobe=cheb2&n={}", 1 + k % 997),
            _ => "/".to_owned(),
        };
        let mut stream = tokio::net::TcpStream::connect(address)
            .await
            .expect("connect");
        let head = format!("GET {path} HTTP/1.1\r\nHost: {address}\r\nConnection: close\r\n\r\n");
        stream.write_all(head.as_bytes()).await.expect("send");
        let mut response = Vec::new();
        stream.read_to_end(&mut response).await.expect("receive");
        let status_line = String::from_utf8_lossy(&response[..response.len().min(12)]).into_owned();
        (path, status_line)
    };
    let load = async {
        let mut failures = Vec::new();
        for batch in 0..10 {
            let handles: Vec<_> = (0..40)
                .map(|k| tokio::spawn(request(batch * 40 + k)))
                .collect();
            for handle in handles {
                let (path, status) = handle.await.expect("task");
                if status != "HTTP/1.1 200" {
                    failures.push((path, status));
                }
            }
        }
        failures
    };
    let failures = tokio::time::timeout(std::time::Duration::from_secs(300), load)
        .await
        .expect("400 requests within the time bound");
    assert!(failures.is_empty(), "{failures:?}");
    if let (Some(before), Some(after)) = (before, resident_kib()) {
        assert!(
            after < before + 512 * 1024,
            "resident memory grew from {before} KiB to {after} KiB"
        );
    }
}
