//! A `volray view` process for the tests: started on a free port, its URL
//! read from the first line of its standard output, its counters read
//! from `/api/status`, stopped with a signal.
#![allow(dead_code)] // each test binary uses part of this

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// A running `volray view`.
pub struct Viewer {
    child: Child,
    /// The URL it printed, token included.
    pub url: String,
    /// `127.0.0.1:PORT`.
    pub host: String,
    pub token: String,
}

impl Viewer {
    /// Starts `volray view ARGS --port 0 --no-browser` and reads its URL:
    /// the `volray` this test was built with, or `VOLRAY_VIEW_BIN` (a
    /// benchmark alternating a baseline build with this one).
    pub fn start(args: &[&str]) -> Viewer {
        let volray = std::env::var_os("VOLRAY_VIEW_BIN")
            .unwrap_or_else(|| env!("CARGO_BIN_EXE_volray").into());
        let mut child = Command::new(volray)
            .arg("view")
            .args(args)
            .args(["--port", "0", "--no-browser"])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("volray view starts");
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        let url = line.trim().to_string();
        let rest = url
            .strip_prefix("http://")
            .unwrap_or_else(|| panic!("the first line is not a URL: {url:?}"));
        let (host, query) = rest.split_once("/?token=").expect("a URL with a token");
        Viewer {
            host: host.to_string(),
            token: query.to_string(),
            url,
            child,
        }
    }

    /// The process id, for signals.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// `GET path` (with its query, as given): the status code and body.
    pub fn get(&self, path: &str) -> (u16, String) {
        http_get(&self.host, path, &[])
    }

    /// `/api/status` as JSON.
    pub fn status(&self) -> serde_json::Value {
        let (code, body) = self.get(&format!("/api/status?token={}", self.token));
        assert_eq!(code, 200, "{body}");
        serde_json::from_str(&body).unwrap()
    }

    /// Waits until the status satisfies `ready`, for at most `limit`.
    pub fn wait_status(&self, limit: Duration, ready: impl Fn(&serde_json::Value) -> bool) {
        let start = Instant::now();
        loop {
            let status = self.status();
            if ready(&status) {
                return;
            }
            assert!(
                start.elapsed() < limit,
                "the server's status stayed {status}"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// Sends `signal` (`TERM`, `INT`) and waits for the exit, for at most
    /// `limit`.
    pub fn stop(mut self, signal: &str, limit: Duration) -> ExitStatus {
        let sent = Command::new("kill")
            .args([format!("-{signal}"), self.child.id().to_string()])
            .status()
            .unwrap();
        assert!(sent.success());
        let start = Instant::now();
        loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                return status;
            }
            if start.elapsed() > limit {
                let _ = self.child.kill();
                panic!("volray view still running {limit:?} after SIG{signal}");
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A bare HTTP/1.1 `GET` with extra header lines: the status code and the
/// body.
pub fn http_get(host: &str, path: &str, headers: &[&str]) -> (u16, String) {
    let mut stream = TcpStream::connect(host).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(20)))
        .unwrap();
    let mut request = format!("GET {path} HTTP/1.1\r\nHost: {host}\r\n");
    if !headers.iter().any(|h| h.starts_with("Connection:")) {
        request.push_str("Connection: close\r\n");
    }
    for h in headers {
        request.push_str(h);
        request.push_str("\r\n");
    }
    request.push_str("\r\n");
    stream.write_all(request.as_bytes()).unwrap();
    // To the end, or to the end of a response on a connection kept open.
    let mut response = Vec::new();
    let mut chunk = [0u8; 4096];
    loop {
        let n = stream.read(&mut chunk).unwrap();
        response.extend_from_slice(&chunk[..n]);
        if n == 0 || complete(&response) {
            break;
        }
    }
    let text = String::from_utf8_lossy(&response).into_owned();
    let code = text
        .split(' ')
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or_else(|| panic!("not an HTTP response: {text:.200}"));
    let body = text
        .split_once("\r\n\r\n")
        .map_or(String::new(), |(_, b)| b.to_string());
    (code, body)
}

/// Whether `response` is whole: a switch to WebSocket's head, or a head
/// and the `Content-Length` bytes it announces.
fn complete(response: &[u8]) -> bool {
    let Some(end) = response.windows(4).position(|w| w == b"\r\n\r\n") else {
        return false;
    };
    let head = String::from_utf8_lossy(&response[..end]).to_ascii_lowercase();
    if head.starts_with("http/1.1 101") {
        return true;
    }
    head.lines()
        .find_map(|l| l.strip_prefix("content-length:"))
        .and_then(|n| n.trim().parse::<usize>().ok())
        .is_some_and(|n| response.len() >= end + 4 + n)
}
