//! A WebDriver client for the browser test: headless Chromium driven by
//! chromedriver over the W3C WebDriver protocol (JSON over HTTP/1.1 on
//! localhost), on `std::net::TcpStream` and serde_json. Written from the
//! W3C WebDriver recommendation (https://www.w3.org/TR/webdriver2/):
//!
//! - "The remote end [...] responds to HTTP requests" with a body that is
//!   "a JSON Object with a single member `value`" (section 6.6, "Processing
//!   model"; errors carry `value.error` and `value.message`);
//! - New Session `POST /session` with `capabilities.alwaysMatch`
//!   (section 8.1), Delete Session `DELETE /session/{id}`;
//! - Navigate To `POST /session/{id}/url` with `{"url": ...}`, which
//!   returns once "the current top-level browsing context's document
//!   readiness state is complete" (section 10.1, page load strategy
//!   `normal`);
//! - Set Window Rect `POST /session/{id}/window/rect` (section 11.8.2);
//! - Execute Script `POST /session/{id}/execute/sync` with `script` (a
//!   function body) and `args` (section 13.2.1);
//! - Print Page `POST /session/{id}/print`: "page" `width` and `height`
//!   in cm, `background`; the result is "a Base64 encoded PDF" (section
//!   18.1).
//!
//! Chromedriver's own: `goog:chromeOptions` (`binary`, `args`) and the
//! browser's console log, `POST /session/{id}/se/log` with `{"type":
//! "browser"}` (entries with `level` and `message`), kept by chromedriver
//! from the JSON Wire Protocol.

use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

/// Installs chromium and chromedriver when either is missing
/// (`scripts/install-browser.sh`, Debian's packages).
pub fn ensure_browser() {
    let have = |cmd: &str| {
        Command::new("sh")
            .args(["-c", &format!("command -v {cmd}")])
            .stdout(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    };
    if have("chromium") && have("chromedriver") {
        return;
    }
    let script = crate::support::workspace().join("scripts/install-browser.sh");
    let status = Command::new("bash").arg(&script).status();
    assert!(
        status.is_ok_and(|s| s.success()) && have("chromium") && have("chromedriver"),
        "the browser test needs chromium and chromedriver, and {} could not install them (Debian: apt-get install -y chromium chromium-driver, as root)",
        script.display()
    );
}

/// One HTTP/1.1 exchange with the driver: the response's status and its
/// JSON body.
fn exchange(port: u16, method: &str, path: &str, body: Option<&Value>) -> (u16, Value) {
    let mut stream = TcpStream::connect(("127.0.0.1", port)).expect("chromedriver is listening");
    stream
        .set_read_timeout(Some(Duration::from_secs(120)))
        .unwrap();
    let body = body.map(Value::to_string).unwrap_or_default();
    let request = format!(
        "{method} {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Type: application/json; charset=utf-8\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    );
    stream.write_all(request.as_bytes()).unwrap();
    // The response: its header, then a body of Content-Length bytes or
    // chunks up to the last (the driver may keep the connection open).
    let mut raw = Vec::new();
    let mut buf = [0u8; 65536];
    let split = loop {
        if let Some(i) = raw.windows(4).position(|w| w == b"\r\n\r\n") {
            break i;
        }
        let n = stream.read(&mut buf).unwrap();
        assert!(
            n > 0,
            "{method} {path}: the connection closed before a response"
        );
        raw.extend_from_slice(&buf[..n]);
    };
    let head = String::from_utf8_lossy(&raw[..split]).to_ascii_lowercase();
    let mut payload = raw[split + 4..].to_vec();
    let status: u16 = head
        .split_whitespace()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .expect("a status code");
    let length = head.lines().find_map(|l| {
        l.strip_prefix("content-length:")
            .and_then(|v| v.trim().parse::<usize>().ok())
    });
    let chunked = head.contains("transfer-encoding: chunked");
    loop {
        let complete = match length {
            Some(n) => payload.len() >= n,
            None if chunked => payload.ends_with(b"0\r\n\r\n"),
            None => false,
        };
        if complete {
            break;
        }
        let n = stream.read(&mut buf).unwrap();
        if n == 0 {
            break;
        }
        payload.extend_from_slice(&buf[..n]);
    }
    if chunked {
        payload = dechunk(&payload);
    }
    let value = serde_json::from_slice(&payload).unwrap_or(Value::Null);
    (status, value)
}

/// The body of a chunked transfer (RFC 9112, section 7.1).
fn dechunk(mut data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    while let Some(end) = data.windows(2).position(|w| w == b"\r\n") {
        let size_text = String::from_utf8_lossy(&data[..end]);
        let size = usize::from_str_radix(size_text.split(';').next().unwrap_or("").trim(), 16)
            .unwrap_or(0);
        if size == 0 {
            break;
        }
        let start = end + 2;
        out.extend_from_slice(&data[start..start + size]);
        data = &data[start + size + 2..];
    }
    out
}

/// A chromedriver process of this test, ended (by its own id) when
/// dropped.
pub struct Driver {
    child: Child,
    port: u16,
}

impl Driver {
    /// Starts chromedriver on a free port and waits until it is ready.
    pub fn start() -> Driver {
        let port = TcpListener::bind("127.0.0.1:0")
            .and_then(|l| l.local_addr())
            .map(|a| a.port())
            .unwrap();
        let child = Command::new("chromedriver")
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("chromedriver starts");
        let driver = Driver { child, port };
        let start = Instant::now();
        loop {
            if TcpStream::connect(("127.0.0.1", port)).is_ok() {
                let (_, v) = exchange(port, "GET", "/status", None);
                if v["value"]["ready"] == true {
                    return driver;
                }
            }
            assert!(
                start.elapsed() < Duration::from_secs(20),
                "chromedriver did not get ready"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// A headless Chromium session with a new, empty profile.
    pub fn session(&self) -> Session<'_> {
        let profile = std::env::temp_dir().join(format!(
            "tricept-report-chromium-{}-{}",
            std::process::id(),
            self.port
        ));
        let _ = std::fs::remove_dir_all(&profile);
        std::fs::create_dir_all(&profile).unwrap();
        let args = [
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--disable-dev-shm-usage",
            &format!("--user-data-dir={}", profile.display()),
        ];
        let caps = json!({"capabilities": {"alwaysMatch": {
            "browserName": "chrome",
            "goog:loggingPrefs": {"browser": "ALL"},
            "goog:chromeOptions": {"binary": chromium(), "args": args},
        }}});
        let (status, v) = exchange(self.port, "POST", "/session", Some(&caps));
        assert_eq!(status, 200, "new session: {v}");
        let id = v["value"]["sessionId"].as_str().unwrap().to_string();
        Session {
            driver: self,
            id,
            profile,
        }
    }
}

/// The chromium binary on PATH.
fn chromium() -> String {
    let out = Command::new("sh")
        .args(["-c", "command -v chromium"])
        .output()
        .unwrap();
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

impl Drop for Driver {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A browser session, deleted (the browser closed) when dropped.
pub struct Session<'a> {
    driver: &'a Driver,
    id: String,
    profile: PathBuf,
}

impl Session<'_> {
    /// A command of this session: its `value`, or a failure naming it.
    pub fn command(&self, method: &str, path: &str, body: Option<Value>) -> Value {
        let (status, v) = exchange(
            self.driver.port,
            method,
            &format!("/session/{}{path}", self.id),
            body.as_ref(),
        );
        assert_eq!(status, 200, "{method} {path}: {v}");
        v["value"].clone()
    }

    /// Opens a local file.
    pub fn open(&self, file: &Path) {
        let url = format!("file://{}", std::fs::canonicalize(file).unwrap().display());
        self.command("POST", "/url", Some(json!({"url": url})));
    }

    /// Sets the window's size (CSS pixels).
    pub fn window(&self, width: u32, height: u32) {
        self.command(
            "POST",
            "/window/rect",
            Some(json!({"width": width, "height": height})),
        );
    }

    /// Runs a script (a function body) in the page; its return value.
    pub fn script(&self, body: &str) -> Value {
        self.command(
            "POST",
            "/execute/sync",
            Some(json!({"script": body, "args": []})),
        )
    }

    /// The browser console's entries since the last call.
    pub fn console(&self) -> Vec<Value> {
        self.command("POST", "/se/log", Some(json!({"type": "browser"})))
            .as_array()
            .cloned()
            .unwrap_or_default()
    }

    /// The page printed to PDF on A4 paper (21 x 29.7 cm), backgrounds
    /// included.
    pub fn print_a4(&self) -> Vec<u8> {
        let v = self.command(
            "POST",
            "/print",
            Some(json!({"page": {"width": 21.0, "height": 29.7}, "background": true})),
        );
        base64(v.as_str().unwrap_or_default())
    }
}

impl Drop for Session<'_> {
    fn drop(&mut self) {
        let _ = exchange(
            self.driver.port,
            "DELETE",
            &format!("/session/{}", self.id),
            None,
        );
        let _ = std::fs::remove_dir_all(&self.profile);
    }
}

/// Base64 (RFC 4648, section 4, with padding) decoded.
pub fn base64(text: &str) -> Vec<u8> {
    let value = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return None,
        } as u32)
    };
    let mut out = Vec::with_capacity(text.len() * 3 / 4);
    let (mut acc, mut bits) = (0u32, 0u32);
    for c in text.bytes() {
        let Some(v) = value(c) else { continue };
        acc = (acc << 6) | v;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    out
}

#[test]
fn base64_decodes_the_rfc_4648_test_vectors() {
    for (text, want) in [
        ("", ""),
        ("Zg==", "f"),
        ("Zm8=", "fo"),
        ("Zm9v", "foo"),
        ("Zm9vYg==", "foob"),
        ("Zm9vYmE=", "fooba"),
        ("Zm9vYmFy", "foobar"),
    ] {
        assert_eq!(base64(text), want.as_bytes(), "{text}");
    }
}

#[test]
fn chunked_bodies_are_joined() {
    assert_eq!(
        dechunk(b"4\r\nWiki\r\n5\r\npedia\r\n0\r\n\r\n"),
        b"Wikipedia"
    );
}
