//! A headless Chromium driven over WebDriver (Debian's `chromium` and
//! `chromium-driver`), and what the tests ask of the viewer's page: wait
//! for its hooks, read its still frame and its Command box, drag.
//!
//! Without the browser or the driver the tests print a note and pass,
//! except under `CI=true`, where they fail: CI installs both.
#![allow(dead_code)] // each test binary uses part of this

use fantoccini::actions::{
    Actions, InputSource, KeyAction, KeyActions, MOUSE_BUTTON_LEFT, MouseActions, PointerAction,
    WheelAction, WheelActions,
};
use fantoccini::{Client, ClientBuilder, Locator};
use serde_json::{Value, json};
use std::net::TcpListener;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

pub const CHROMIUM: &str = "/usr/bin/chromium";
pub const CHROMEDRIVER: &str = "/usr/bin/chromedriver";

/// How long a page may take to reach a state before the test fails: far
/// more than it needs (tens of milliseconds), so that a slow machine never
/// fails a test, while a broken page does not hang it.
pub const PATIENCE: Duration = Duration::from_secs(60);

/// A chromedriver and one browser session.
pub struct Browser {
    pub client: Client,
    driver: Child,
    _profile: tempfile::TempDir,
}

/// Whether the browser and its driver are installed: `false` (with a
/// note) where the tests may skip, a panic under `CI=true`.
pub fn available() -> bool {
    let missing: Vec<&str> = [CHROMIUM, CHROMEDRIVER]
        .into_iter()
        .filter(|p| !Path::new(p).exists())
        .collect();
    if missing.is_empty() {
        return true;
    }
    let note = format!(
        "{} not installed (apt-get install chromium chromium-driver)",
        missing.join(" and ")
    );
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("CI=true: the browser tests need a browser: {note}");
    }
    eprintln!("note: skipping a browser test: {note}");
    false
}

impl Browser {
    /// Starts chromedriver and a headless Chromium with a fresh profile.
    pub async fn start() -> Browser {
        let port = TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let driver = Command::new(CHROMEDRIVER)
            .arg(format!("--port={port}"))
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("chromedriver starts");
        let profile = tempfile::tempdir().unwrap();
        let capabilities = json!({
            "goog:chromeOptions": {
                "binary": CHROMIUM,
                "args": [
                    "--headless", "--no-sandbox", "--disable-gpu",
                    "--disable-background-networking", "--disable-component-update",
                    "--disable-sync", "--no-first-run", "--disable-dev-shm-usage",
                    "--window-size=1000,760",
                    format!("--user-data-dir={}", profile.path().display()),
                ]
            }
        });
        let Value::Object(capabilities) = capabilities else {
            unreachable!()
        };
        let connector = hyper_util::client::legacy::connect::HttpConnector::new();
        let start = Instant::now();
        let client = loop {
            let mut builder = ClientBuilder::new(connector.clone());
            builder.capabilities(capabilities.clone());
            match builder.connect(&format!("http://127.0.0.1:{port}")).await {
                Ok(client) => break client,
                Err(e) if start.elapsed() < PATIENCE => {
                    let _ = e;
                    tokio::time::sleep(Duration::from_millis(50)).await;
                }
                Err(e) => panic!("no WebDriver session: {e}"),
            }
        };
        Browser {
            client,
            driver,
            _profile: profile,
        }
    }

    /// Ends the session (the browser quits) and the driver.
    pub async fn close(self) {
        let _ = self.client.clone().close().await;
        // Drop ends the driver.
    }

    /// The value of a script's `return`.
    pub async fn eval(&self, script: &str) -> Value {
        self.client
            .execute(script, vec![])
            .await
            .unwrap_or_else(|e| panic!("{script}: {e}"))
    }

    /// Waits until `expression` is true in the page.
    pub async fn wait_for(&self, expression: &str) {
        let start = Instant::now();
        loop {
            if self.eval(&format!("return !!({expression});")).await == json!(true) {
                return;
            }
            if start.elapsed() > PATIENCE {
                let error = self
                    .eval("return document.getElementById('error').textContent;")
                    .await;
                panic!("the page never had {expression} (error box: {error})");
            }
            tokio::time::sleep(Duration::from_millis(10)).await;
        }
    }

    /// Frames the page has shown.
    pub async fn frames(&self) -> u64 {
        let v = self.eval("return document.body.dataset.frames;").await;
        v.as_str().unwrap().parse().unwrap()
    }

    /// Waits for the full-quality frame of the current state.
    pub async fn wait_still(&self) {
        self.wait_for("document.body.dataset.state === 'still'")
            .await;
    }

    /// The PNG the page shows in `#frame`, as the server sent it.
    pub async fn frame_bytes(&self) -> Vec<u8> {
        let script = r#"
            const done = arguments[arguments.length - 1];
            fetch(document.getElementById('frame').src)
              .then((r) => r.arrayBuffer())
              .then((b) => {
                let s = '';
                for (const x of new Uint8Array(b)) s += String.fromCharCode(x);
                done(btoa(s));
              })
              .catch((e) => done('error: ' + e));
        "#;
        let value = self.client.execute_async(script, vec![]).await.unwrap();
        let text = value.as_str().unwrap();
        assert!(!text.starts_with("error"), "{text}");
        base64_decode(text)
    }

    /// The text of the element with `id`.
    pub async fn text(&self, id: &str) -> String {
        let v = self
            .eval(&format!(
                "return document.getElementById('{id}').textContent;"
            ))
            .await;
        v.as_str().unwrap().to_string()
    }

    /// Drags the mouse over the element `selector` from `from` (relative
    /// to its centre) by `by` pixels, in `steps` moves.
    pub async fn drag(&self, selector: &str, from: (f64, f64), by: (f64, f64), steps: u32) {
        self.drag_holding(selector, from, by, steps, false).await;
    }

    /// [`Self::drag`], holding shift when `shift`.
    pub async fn drag_holding(
        &self,
        selector: &str,
        from: (f64, f64),
        by: (f64, f64),
        steps: u32,
        shift: bool,
    ) {
        let element = self.client.find(Locator::Css(selector)).await.unwrap();
        let mut mouse = MouseActions::new("mouse".to_string())
            .then(PointerAction::MoveToElement {
                element,
                duration: None,
                x: from.0,
                y: from.1,
            })
            .then(PointerAction::Down {
                button: MOUSE_BUTTON_LEFT,
            });
        for _ in 0..steps {
            mouse = mouse.then(PointerAction::MoveBy {
                duration: Some(Duration::from_millis(16)),
                x: (by.0 / steps as f64).round(),
                y: (by.1 / steps as f64).round(),
            });
        }
        mouse = mouse.then(PointerAction::Up {
            button: MOUSE_BUTTON_LEFT,
        });
        let mut actions = Actions::from(mouse);
        if shift {
            // One key action a tick: shift is down before the button is.
            let shift_key = '\u{e008}';
            let mut keys =
                KeyActions::new("keys".to_string()).then(KeyAction::Down { value: shift_key });
            for _ in 0..steps + 2 {
                keys = keys.then(KeyAction::Pause {
                    duration: Duration::ZERO,
                });
            }
            actions = actions.and(keys.then(KeyAction::Up { value: shift_key }));
        }
        self.client.perform_actions(actions).await.unwrap();
        self.client.release_actions().await.unwrap();
    }

    /// Turns the wheel by `delta_y` pixels over the centre of `selector`.
    pub async fn wheel(&self, selector: &str, delta_y: i64) {
        let centre = self
            .eval(&format!(
                "const r = document.querySelector('{selector}').getBoundingClientRect(); return [r.x + r.width / 2, r.y + r.height / 2];"
            ))
            .await;
        let wheel = WheelActions::new("wheel".to_string()).then(WheelAction::Scroll {
            duration: None,
            x: centre[0].as_f64().unwrap() as i64,
            y: centre[1].as_f64().unwrap() as i64,
            delta_x: 0,
            delta_y,
        });
        self.client.perform_actions(wheel).await.unwrap();
    }

    /// A double click at the centre of `selector`.
    pub async fn double_click(&self, selector: &str) {
        self.clicks(selector, (0.0, 0.0), 2).await;
    }

    /// A click at (`x`, `y`) from the centre of the element `selector`.
    pub async fn click_at(&self, selector: &str, x: f64, y: f64) {
        self.clicks(selector, (x, y), 1).await;
    }

    /// Clicks the element `selector` (a CSS selector) as WebDriver does.
    pub async fn click(&self, selector: &str) {
        let element = self.client.find(Locator::Css(selector)).await.unwrap();
        element.click().await.unwrap();
    }

    /// Moves the pointer (no button) to `at` from the centre of the
    /// element `selector`.
    pub async fn hover(&self, selector: &str, at: (f64, f64)) {
        let element = self.client.find(Locator::Css(selector)).await.unwrap();
        let mouse = MouseActions::new("mouse".to_string()).then(PointerAction::MoveToElement {
            element,
            duration: None,
            x: at.0,
            y: at.1,
        });
        self.client.perform_actions(mouse).await.unwrap();
        self.client.release_actions().await.unwrap();
    }

    /// `n` clicks at `at` from the centre of the element `selector`.
    async fn clicks(&self, selector: &str, at: (f64, f64), n: usize) {
        let element = self.client.find(Locator::Css(selector)).await.unwrap();
        let mut mouse = MouseActions::new("mouse".to_string()).then(PointerAction::MoveToElement {
            element,
            duration: None,
            x: at.0,
            y: at.1,
        });
        for _ in 0..n {
            mouse = mouse
                .then(PointerAction::Down {
                    button: MOUSE_BUTTON_LEFT,
                })
                .then(PointerAction::Up {
                    button: MOUSE_BUTTON_LEFT,
                });
        }
        self.client.perform_actions(mouse).await.unwrap();
        self.client.release_actions().await.unwrap();
    }
}

/// A test that fails before [`Browser::close`] would leave the browser
/// running: the driver and every process under it are ended here.
impl Drop for Browser {
    fn drop(&mut self) {
        let mut tree = vec![self.driver.id()];
        let mut i = 0;
        while i < tree.len() {
            tree.extend(children(tree[i]));
            i += 1;
        }
        for pid in tree.iter().skip(1).rev() {
            let _ = Command::new("kill")
                .args(["-KILL", &pid.to_string()])
                .status();
        }
        let _ = self.driver.kill();
        let _ = self.driver.wait();
    }
}

/// The processes whose parent is `pid`, from `/proc`.
fn children(pid: u32) -> Vec<u32> {
    let Ok(entries) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    entries
        .filter_map(|e| e.ok()?.file_name().to_str()?.parse::<u32>().ok())
        .filter(|child| {
            std::fs::read_to_string(format!("/proc/{child}/stat")).is_ok_and(|stat| {
                // pid (comm) state ppid ...: the comm may hold spaces.
                stat.rsplit_once(')')
                    .and_then(|(_, rest)| rest.split_whitespace().nth(1)?.parse::<u32>().ok())
                    == Some(pid)
            })
        })
        .collect()
}

/// Standard base64, as `btoa` writes it.
pub fn base64_decode(text: &str) -> Vec<u8> {
    let value = |c: u8| -> u32 {
        match c {
            b'A'..=b'Z' => u32::from(c - b'A'),
            b'a'..=b'z' => u32::from(c - b'a') + 26,
            b'0'..=b'9' => u32::from(c - b'0') + 52,
            b'+' => 62,
            b'/' => 63,
            _ => panic!("not base64: {c}"),
        }
    };
    let bytes: Vec<u8> = text.bytes().filter(|&c| c != b'=').collect();
    let mut out = Vec::with_capacity(bytes.len() * 3 / 4);
    for chunk in bytes.chunks(4) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |n, (i, &c)| n | value(c) << (18 - 6 * i));
        let keep = chunk.len() - 1;
        out.extend_from_slice(&n.to_be_bytes()[1..1 + keep]);
    }
    out
}

#[test]
fn base64_decodes_what_btoa_writes() {
    assert_eq!(base64_decode("aGVsbG8="), b"hello");
    assert_eq!(base64_decode("aGVsbG8hIQ=="), b"hello!!");
    assert_eq!(base64_decode("YWJj"), b"abc");
}
