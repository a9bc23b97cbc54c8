//! `volray view` end to end, in a real headless Chromium driven over
//! WebDriver: the first frame appears; a drag changes the image and the
//! azimuth in the Command box; a transfer-function edit changes the
//! image; the Command line, run through the CLI, writes the page's still
//! frame pixel for pixel; bad messages are answered in the page and the
//! server goes on; two tabs are independent and a closed tab frees its
//! renderer; a burst of 1,000 requests is not queued; a slow frame is
//! stopped by a newer request and by closing its tab; two tabs' frames
//! together are held within `--max-memory`. Without a browser
//! these skip with a note, except under `CI=true`, where they fail.
//!
//! The token and the signals need no browser: a bare HTTP client and
//! `kill` check them.

#[path = "view_support/browser.rs"]
mod browser;
mod common;
#[path = "view_support/viewer.rs"]
mod viewer;

use browser::Browser;
use common::Picture;
use std::process::Command;
use std::time::Duration;
use viewer::{Viewer, http_get};

/// Reads the azimuth from a command line (0 when it gives none).
fn azimuth(command: &str) -> f64 {
    let words: Vec<&str> = command.split_whitespace().collect();
    words
        .iter()
        .position(|w| *w == "--azimuth")
        .map_or(0.0, |i| words[i + 1].parse().unwrap())
}

/// A viewer of `args` and a browser showing its first full frame; `None`
/// where the browser tests skip (see `browser::available`).
async fn open(args: &[&str]) -> Option<(Viewer, Browser)> {
    if !browser::available() {
        return None;
    }
    let viewer = Viewer::start(args);
    let b = Browser::start().await;
    b.client.goto(&viewer.url).await.unwrap();
    b.wait_still().await;
    Some((viewer, b))
}

/// Decodes PNG bytes.
fn picture(bytes: &[u8], dir: &std::path::Path, name: &str) -> Picture {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    Picture::read(&path)
}

/// Runs the page's Command line (and writes its transfer-function file)
/// in `dir` with this build's `volray`; the image it writes.
fn run_command(command: &str, tf_file: Option<(&str, &str)>, dir: &std::path::Path) -> Picture {
    run_with_files(command, tf_file.into_iter().collect(), dir)
}

/// Runs the page's Command line with every file the last frame's header
/// names (the `--tf` file and a scene's `--overlay` files); the image.
async fn run_shown(b: &Browser, dir: &std::path::Path) -> Picture {
    let header = b.eval("return window.volrayView.header();").await;
    let mut files: Vec<(String, String)> = Vec::new();
    if let Some([name, json]) = header["tf_file"].as_array().map(|f| [&f[0], &f[1]]) {
        files.push((name.as_str().unwrap().into(), json.as_str().unwrap().into()));
    }
    for f in header["layer_tf_files"].as_array().into_iter().flatten() {
        files.push((f[0].as_str().unwrap().into(), f[1].as_str().unwrap().into()));
    }
    let command = header["command"].as_str().unwrap();
    let files = files
        .iter()
        .map(|(n, j)| (n.as_str(), j.as_str()))
        .collect();
    run_with_files(command, files, dir)
}

fn run_with_files(command: &str, files: Vec<(&str, &str)>, dir: &std::path::Path) -> Picture {
    for (name, json) in files {
        std::fs::write(dir.join(name), json).unwrap();
    }
    let line = command
        .strip_prefix("volray ")
        .expect("the command starts with volray");
    let status = Command::new("sh")
        .arg("-c")
        .arg(format!("\"$VOLRAY\" {line}"))
        .env("VOLRAY", env!("CARGO_BIN_EXE_volray"))
        .current_dir(dir)
        .status()
        .unwrap();
    assert!(status.success(), "{command}");
    Picture::read(&dir.join("view.png"))
}

#[tokio::test(flavor = "current_thread")]
async fn a_page_started_with_no_transfer_function_shows_the_one_chosen_and_names_it() {
    // No --tf, --preset or --colormap: `render` would choose one from the
    // data (`--tf auto`); the page starts from it, and its command gives
    // the still frame with that choice written out.
    let Some((_viewer, b)) = open(&["blobs:32", "--size", "96"]).await else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let still = picture(&b.frame_bytes().await, dir.path(), "still.png");
    let command = b.text("command").await;
    assert!(command.contains("--tf view-tf.json"), "{command}");
    let tf_json = b.text("tf-json").await;
    assert!(
        tf_json.contains("\"opacity\"") && tf_json.contains("\"color\""),
        "{tf_json}"
    );
    let cli = run_command(&command, Some(("view-tf.json", &tf_json)), dir.path());
    assert_eq!(cli, still, "the CLI's image differs from the page's");
    // And it is what `render` draws with no options.
    let plain = dir.path().join("plain.png");
    let out = common::volray(&[
        "render",
        "blobs:32",
        "--size",
        "96",
        "-o",
        plain.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    assert_eq!(Picture::read(&plain), still);
    b.close().await;
}

#[tokio::test(flavor = "current_thread")]
async fn a_label_volumes_page_names_its_labels_and_reproduces_its_frame() {
    let seg = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crates/io/tests/fixtures/labels/seg.nii.gz"
    );
    let Some((_viewer, b)) = open(&[seg, "--labels", "--size", "64"]).await else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let still = picture(&b.frame_bytes().await, dir.path(), "still.png");
    let command = b.text("command").await;
    assert!(
        command.contains("--labels") && command.contains("--tf view-tf.json"),
        "{command}"
    );
    let tf_json = b.text("tf-json").await;
    let cli = run_command(&command, Some(("view-tf.json", &tf_json)), dir.path());
    assert_eq!(cli, still, "the CLI's image differs from the page's");
    b.close().await;
}

#[tokio::test(flavor = "current_thread")]
async fn a_segmentations_page_draws_its_labels_in_the_files_colours_as_render_does() {
    // The DICOM Segmentation's segments are "bone" red and "vessel" blue,
    // which neither palette colour of labels 1 and 2 (orange, green) is.
    let seg = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crates/io/tests/fixtures/dicom/seg.dcm"
    );
    let Some((_viewer, b)) = open(&[seg, "--labels", "--size", "48"]).await else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let still = picture(&b.frame_bytes().await, dir.path(), "still.png");
    let bluish = |&[r, g, b]: &[u8; 3]| b > 40 && b > r.max(g).saturating_add(10);
    let reddish = |&[r, g, b]: &[u8; 3]| r > 40 && u16::from(r) > 2 * u16::from(g.max(b));
    assert!(
        still.rgb.iter().any(bluish),
        "no blue: the file's colours unused"
    );
    assert!(
        still.rgb.iter().any(reddish),
        "no red: the file's colours unused"
    );
    let command = b.text("command").await;
    let tf_json = b.text("tf-json").await;
    let cli = run_command(&command, Some(("view-tf.json", &tf_json)), dir.path());
    assert_eq!(cli, still, "the CLI's image differs from the page's");
    b.close().await;
}

#[tokio::test(flavor = "current_thread")]
async fn the_page_renders_orbits_edits_and_its_command_reproduces_the_still_frame() {
    if !browser::available() {
        return;
    }
    let viewer = Viewer::start(&["blobs:48", "--size", "240", "--colormap", "viridis"]);
    let b = Browser::start().await;
    let dir = tempfile::tempdir().unwrap();

    // A wrong token gets 403, in the browser too.
    let base = viewer.url.split("?token=").next().unwrap().to_string();
    b.client.goto(&format!("{base}?token=0123")).await.unwrap();
    let body = b.eval("return document.body.textContent;").await;
    assert!(body.as_str().unwrap().contains("403"), "{body}");

    // The first frame.
    b.client.goto(&viewer.url).await.unwrap();
    b.wait_still().await;
    assert!(b.frames().await >= 1);
    let first = picture(&b.frame_bytes().await, dir.path(), "first.png");
    assert_eq!((first.width, first.height), (240, 240));
    let command = b.text("command").await;
    assert!(
        command.starts_with("volray render blobs:48 --size 240x240"),
        "{command}"
    );
    assert_eq!(azimuth(&command), 0.0);

    // A drag orbits: another image, another azimuth.
    let shown = b.frames().await;
    b.drag("#frame", (0.0, 0.0), (80.0, 0.0), 8).await;
    b.wait_still().await;
    assert!(b.frames().await > shown);
    let orbited = picture(&b.frame_bytes().await, dir.path(), "orbited.png");
    assert_ne!(orbited, first, "the drag did not change the image");
    let command = b.text("command").await;
    assert!(azimuth(&command) < -10.0, "{command}");

    // A transfer-function edit: a click on the editor adds an opaque point.
    b.click_at("#tf", -40.0, -60.0).await;
    b.wait_still().await;
    let edited = picture(&b.frame_bytes().await, dir.path(), "edited.png");
    assert_ne!(edited, orbited, "the edit did not change the image");
    let command = b.text("command").await;
    assert!(command.contains("--tf view-tf.json"), "{command}");
    let tf_name = b.text("tf-name").await;
    let tf_json = b.text("tf-json").await;
    assert_eq!(tf_name, "view-tf.json");
    assert!(tf_json.contains("\"opacity\""), "{tf_json}");

    // The command line, run through the CLI, gives the still frame.
    let cli = run_command(&command, Some((&tf_name, &tf_json)), dir.path());
    assert_eq!(
        cli, edited,
        "the CLI's image differs from the page's still frame"
    );

    // A screenshot of the page, for the docs (docs/viewer.png).
    if let Ok(path) = std::env::var("VOLRAY_VIEW_SCREENSHOT") {
        std::fs::write(path, b.client.screenshot().await.unwrap()).unwrap();
    }

    // Bad messages: an error in the page, and the server goes on.
    let mut state = b.eval("return window.volrayView.state();").await;
    for (message, expect) in [
        ("{".to_string(), "malformed"),
        (
            serde_json::json!({"type": "view", "seq": 1_000_000, "quality": "full",
                "state": {"azimuth": 1}})
            .to_string(),
            "malformed",
        ),
        (
            {
                state["zoom"] = serde_json::Value::Null; // JSON.stringify(NaN)
                serde_json::json!({"type": "view", "seq": 1_000_001, "quality": "full", "state": state}).to_string()
            },
            "malformed",
        ),
        (
            {
                state["zoom"] = 1e9.into();
                serde_json::json!({"type": "view", "seq": 1_000_002, "quality": "full", "state": state}).to_string()
            },
            "zoom 1000000000 is outside",
        ),
    ] {
        let script = format!(
            "window.volrayView.send({}); return true;",
            serde_json::to_string(&message).unwrap()
        );
        b.eval(&script).await;
        b.wait_for(&format!(
            "!document.getElementById('error').hidden && document.getElementById('error').textContent.includes({})",
            serde_json::to_string(expect).unwrap()
        ))
        .await;
    }
    b.eval("window.volrayView.setState({azimuth: 45}); return true;")
        .await;
    b.wait_still().await;
    assert_eq!(azimuth(&b.text("command").await), 45.0);
    assert!(
        b.eval("return document.getElementById('error').hidden;")
            .await
            == serde_json::json!(true)
    );

    // The wheel zooms, a shift-drag pans, a double click resets.
    b.wheel("#frame", -300).await;
    b.wait_for("document.getElementById('command').textContent.includes('--zoom')")
        .await;
    b.wait_still().await;
    b.drag_holding("#frame", (0.0, 0.0), (30.0, -20.0), 4, true)
        .await;
    b.wait_still().await;
    let command = b.text("command").await;
    assert!(command.contains("--look-at"), "{command}");
    assert_eq!(
        azimuth(&command),
        45.0,
        "a shift-drag does not orbit: {command}"
    );
    b.double_click("#frame").await;
    b.wait_for("!document.getElementById('command').textContent.includes('--zoom')")
        .await;
    b.wait_still().await;
    let command = b.text("command").await;
    assert_eq!(azimuth(&command), 0.0, "{command}");
    assert!(!command.contains("--look-at"), "{command}");

    // "Save PNG" at another size.
    b.eval(
        "document.getElementById('save-width').value = 64; \
         document.getElementById('save-height').value = 48; \
         document.getElementById('save').click(); return true;",
    )
    .await;
    b.wait_for("window.volrayView.saved()").await;
    let saved = b.eval("return window.volrayView.saved();").await;
    assert_eq!(
        (saved["width"].as_u64(), saved["height"].as_u64()),
        (Some(64), Some(48))
    );
    assert!(
        saved["command"].as_str().unwrap().contains("--size 64x48"),
        "{saved}"
    );

    b.close().await;
}

#[tokio::test(flavor = "current_thread")]
async fn two_tabs_are_independent_and_a_closed_tab_frees_its_renderer() {
    let Some((viewer, b)) = open(&["fractal:65", "--size", "160"]).await else {
        return;
    };
    let first = b.client.window().await.unwrap();
    let second = b.client.new_window(true).await.unwrap().handle;
    b.client.switch_to_window(second.clone()).await.unwrap();
    b.client.goto(&viewer.url).await.unwrap();
    b.wait_still().await;
    viewer.wait_status(browser::PATIENCE, |s| s["sessions"] == 2);

    // The second tab orbits; the first keeps its view.
    b.eval("window.volrayView.setState({azimuth: 90, colormap: 'magma'}); return true;")
        .await;
    b.wait_still().await;
    assert_eq!(azimuth(&b.text("command").await), 90.0);
    b.client.switch_to_window(first).await.unwrap();
    let command = b.text("command").await;
    assert_eq!(azimuth(&command), 0.0, "{command}");
    assert!(!command.contains("magma"), "{command}");
    b.eval("window.volrayView.setState({elevation: 30}); return true;")
        .await;
    b.wait_still().await;
    let command = b.text("command").await;
    assert!(command.contains("--azimuth 0 --elevation 30"), "{command}");

    // Closing the second tab frees its renderer.
    b.client.switch_to_window(second).await.unwrap();
    b.client.close_window().await.unwrap();
    viewer.wait_status(browser::PATIENCE, |s| s["sessions"] == 1);

    // SIGTERM with a tab still open: the server stops, exit 0.
    let status = viewer.stop("TERM", browser::PATIENCE);
    assert_eq!(status.code(), Some(0));
    b.close().await;
}

#[tokio::test(flavor = "current_thread")]
async fn a_burst_of_a_thousand_requests_renders_the_latest_not_a_queue() {
    let Some((viewer, b)) = open(&["fractal:65", "--size", "160"]).await else {
        return;
    };
    let status = viewer.status();
    let before = status["frames"].as_u64().unwrap() + status["stopped"].as_u64().unwrap();
    // 1,000 drafts in one go, then the full frame of the last state.
    let script = r#"
        const v = window.volrayView;
        for (let i = 0; i < 1000; i++) v.sendState({azimuth: i / 10}, "draft");
        v.sendState({azimuth: 99.9}, "full");
        return true;
    "#;
    b.eval(script).await;
    b.wait_still().await;
    assert_eq!(azimuth(&b.text("command").await), 99.9);
    let after = viewer.status();
    // The frames begun: rendered and sent, or stopped by a newer request.
    let begun =
        |s: &serde_json::Value| s["frames"].as_u64().unwrap() + s["stopped"].as_u64().unwrap();
    let rendered = begun(&after) - before;
    // The mailbox keeps only the latest request: a handful of frames is
    // begun, not one per request (a queue would begin all 1,001, each
    // taken and then stopped by the next).
    assert!(
        rendered <= 100,
        "{rendered} of 1001 requests were begun as frames: the requests were queued"
    );
    eprintln!("burst: {rendered} of 1001 requests rendered");
    b.close().await;
}

/// A 4096² frame at step 0.001: minutes of work on any machine.
const SLOW: &str =
    "window.volrayView.sendState({width: 4096, height: 4096, step: 0.001}); return true;";

/// An ordinary view at `azimuth`.
fn ordinary(azimuth: u32) -> String {
    format!(
        "window.volrayView.sendState({{width: 160, height: 160, step: 1, azimuth: {azimuth}}}); return true;"
    )
}

#[tokio::test(flavor = "current_thread")]
async fn a_slow_frame_is_stopped_by_a_newer_request_and_by_closing_its_tab_and_memory_is_shared() {
    // 800 MiB: one 4096² frame fits (about 460 MiB with its encoding),
    // two do not.
    let Some((viewer, b)) = open(&["fractal:65", "--size", "160", "--max-memory", "800M"]).await
    else {
        return;
    };
    let first = b.client.window().await.unwrap();
    let second = b.client.new_window(true).await.unwrap().handle;
    b.client.switch_to_window(second.clone()).await.unwrap();
    b.client.goto(&viewer.url).await.unwrap();
    b.wait_still().await;

    // The first tab asks for the slow frame.
    b.client.switch_to_window(first.clone()).await.unwrap();
    b.eval(SLOW).await;
    viewer.wait_status(browser::PATIENCE, |s| s["rendering"] == 1);

    // The second tab's 4096² frame does not fit beside it: refused, with
    // the reason in the page, not queued.
    b.client.switch_to_window(second.clone()).await.unwrap();
    b.eval("window.volrayView.sendState({width: 4096, height: 4096}); return true;")
        .await;
    b.wait_for("document.body.dataset.state === 'error'").await;
    let error = b.text("error").await;
    assert!(
        error.starts_with("a 4096x4096 frame needs up to ")
            && error.contains("but the open tabs hold")
            && error.contains("of the memory limit 800 MiB"),
        "{error}"
    );
    assert_eq!(viewer.status()["refused"], 1);

    // An ordinary request in the first tab stops its slow frame; its own
    // frame comes.
    b.client.switch_to_window(first).await.unwrap();
    b.eval(&ordinary(45)).await;
    b.wait_still().await;
    assert_eq!(azimuth(&b.text("command").await), 45.0);
    let status = viewer.status();
    assert_eq!(
        (&status["stopped"], &status["rendering"]),
        (&1.into(), &0.into()),
        "{status}"
    );

    // The second tab starts a slow frame and closes: the frame is
    // stopped, the renderer freed, the server idle.
    b.client.switch_to_window(second).await.unwrap();
    b.eval(SLOW).await;
    viewer.wait_status(browser::PATIENCE, |s| s["rendering"] == 1);
    b.client.close_window().await.unwrap();
    viewer.wait_status(browser::PATIENCE, |s| {
        s["rendering"] == 0 && s["sessions"] == 1 && s["stopped"] == 2
    });
    b.close().await;
}

#[test]
fn every_request_without_the_token_is_refused() {
    let viewer = Viewer::start(&["blobs:16", "--size", "32"]);
    let token = viewer.token.clone();
    let ws = [
        "Upgrade: websocket",
        "Connection: Upgrade",
        "Sec-WebSocket-Version: 13",
        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==",
    ];
    for path in [
        "/",
        "/app.js",
        "/style.css",
        "/api/status",
        "/ws",
        "/nothing",
    ] {
        for query in [
            String::new(),
            "?token=".into(),
            format!("?token={}", &token[1..]),
        ] {
            let (code, _) = http_get(&viewer.host, &format!("{path}{query}"), &ws[..]);
            assert_eq!(code, 403, "{path}{query}");
        }
    }
    let with = |path: &str| format!("{path}?token={token}");
    assert_eq!(viewer.get(&with("/")).0, 200);
    assert_eq!(viewer.get(&with("/app.js")).0, 200);
    assert_eq!(viewer.get(&with("/nothing")).0, 404);
    assert_eq!(http_get(&viewer.host, &with("/ws"), &ws).0, 101);
    // Another site's page cannot open the socket, token or not.
    let foreign = [&ws[..], &["Origin: http://example.org"]].concat();
    assert_eq!(http_get(&viewer.host, &with("/ws"), &foreign).0, 403);
}

#[test]
fn sigterm_and_ctrl_c_stop_the_server_with_exit_0() {
    for signal in ["TERM", "INT"] {
        let viewer = Viewer::start(&["blobs:16", "--size", "32"]);
        assert_eq!(viewer.status()["sessions"], 0);
        let status = viewer.stop(signal, Duration::from_secs(30));
        assert_eq!(status.code(), Some(0), "SIG{signal}");
    }
}

#[test]
fn a_bind_beyond_loopback_warns_and_a_bad_start_is_refused() {
    use std::io::{BufRead, BufReader};
    let mut child = Command::new(env!("CARGO_BIN_EXE_volray"))
        .args([
            "view", "blobs:16", "--size", "32", "--bind", "0.0.0.0", "--port", "0",
        ])
        .arg("--no-browser")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut url = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut url)
        .unwrap();
    assert!(url.starts_with("http://127.0.0.1:"), "{url}");
    let mut warning = String::new();
    BufReader::new(child.stderr.take().unwrap())
        .read_line(&mut warning)
        .unwrap();
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        warning.contains("warning: listening on 0.0.0.0"),
        "{warning}"
    );

    let out = common::volray(&["view", "blobs:16", "--zoom", "0.0001", "--no-browser"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        common::stderr(&out).contains(
            "the starting view is beyond the viewer's bounds: zoom 0.0001 is outside 0.001 to 1000"
        ),
        "{}",
        common::stderr(&out)
    );
    let out = common::volray(&["view", "blobs:16", "--size", "5000", "--no-browser"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        common::stderr(&out).contains(
            "the starting view is beyond the viewer's bounds: width 5000 is outside 1 to 4096"
        ),
        "{}",
        common::stderr(&out)
    );
    let out = common::volray(&["view", "blobs:16", "--blend", "mip", "--opacity", "0,1"]);
    assert_eq!(out.status.code(), Some(1));
}

#[tokio::test(flavor = "current_thread")]
async fn a_pyramids_page_says_which_level_its_still_shows() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("b.ome.zarr");
    let path = path.to_str().unwrap();
    let out = common::volray(&["convert", "blobs:96", "-o", path]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    // 64² stills need the 96³ level; the 32² drafts, the 48³.
    let Some((_viewer, b)) = open(&[path, "--size", "64"]).await else {
        return;
    };
    assert_eq!(b.eval("return document.body.dataset.level;").await, "0");
    let status = b.text("status").await;
    assert!(status.contains("level 0 of 2 (96³)"), "{status}");
    assert!(b.text("volume").await.contains("96×96×96 · 2 levels"));
    b.close().await;
}

/// An OME-Zarr image whose y and x are in degrees and z in metres
/// (zarr-python): a Gaussian blob, 64 × 64 × 32 (x, y, z).
const DEGREES_BY_METRES: &str = r#"
import sys, numpy as np, zarr
k, j, i = np.mgrid[0:32, 0:64, 0:64]
a = np.exp(-((i - 32) ** 2 + (j - 32) ** 2 + (k - 16) ** 2) / 200.0).astype(np.float32)
g = zarr.open_group(sys.argv[1] + "/o.zarr", mode="w", zarr_format=2)
g.create_array("0", shape=a.shape, chunks=(8, 16, 16), dtype="f4")[:] = a
g.attrs["multiscales"] = [{"version": "0.4", "axes": [
    {"name": "z", "type": "space", "unit": "meter"},
    {"name": "y", "type": "space", "unit": "degree"},
    {"name": "x", "type": "space", "unit": "degree"}],
  "datasets": [{"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [100.0, 0.25, 0.25]}]}]}]
"#;

#[tokio::test(flavor = "current_thread")]
async fn a_pyramid_in_degrees_by_metres_is_drawn_stretched_as_render_draws_it() {
    // The viewer opens a chunked file level by level; its levels are
    // stretched by the rule `render` applies to the level it reads, so
    // the page's still is the command's picture, not a line.
    let Some(dir) = common::written_by_python(&["zarr", "numpy"], &[], DEGREES_BY_METRES) else {
        return;
    };
    let path = dir.path().join("o.zarr");
    let Some((_viewer, b)) = open(&[path.to_str().unwrap(), "--size", "48"]).await else {
        return;
    };
    let out = tempfile::tempdir().unwrap();
    let still = picture(&b.frame_bytes().await, out.path(), "still.png");
    let cli = run_shown(&b, out.path()).await;
    let differ = cli.max_diff(&still);
    assert_eq!(differ, 0, "the CLI's image differs from the page's");
    // A box, not the line the stored spacings draw.
    let lit: Vec<(usize, usize)> = (0..still.height)
        .flat_map(|r| (0..still.width).map(move |c| (c, r)))
        .filter(|&(c, r)| still.at(c, r).iter().any(|&v| v > 8))
        .collect();
    let span = |f: fn(&(usize, usize)) -> usize| {
        let v: Vec<usize> = lit.iter().map(f).collect();
        v.iter().max().unwrap_or(&0) - v.iter().min().unwrap_or(&0)
    };
    assert!(
        span(|p| p.0) > 10 && span(|p| p.1) > 10,
        "a line, not a box"
    );
    b.close().await;
}

#[tokio::test(flavor = "current_thread")]
async fn a_scenes_page_has_a_panel_per_volume_and_its_command_reproduces_each_edit() {
    if !browser::available() {
        return;
    }
    use common::nifti::{ball, frame, nifti};
    let dir = tempfile::tempdir().unwrap();
    // Two channels (a ball left, a ball right) and a label volume over
    // both: a slab of label 1 through the middle.
    let stack = nifti(dir.path(), "stack.nii", &[ball(6.0), ball(17.0)]);
    let slab = frame(|_, _, z| if (10.0..14.0).contains(&z) { 1.0 } else { 0.0 });
    let seg = nifti(dir.path(), "seg.nii", &[slab]);
    let overlay = format!("{seg}:labels");
    let Some((_viewer, b)) = open(&[
        &stack,
        "--channels",
        "all",
        "--overlay",
        &overlay,
        "--size",
        "64",
    ])
    .await
    else {
        return;
    };
    let rows = b
        .eval("return document.querySelectorAll('#volumes .volume').length;")
        .await;
    assert_eq!(rows, 3, "one row per volume");
    let command = b.text("command").await;
    for part in [
        "--frame 0",
        ":frame=1,range=",
        "seg.nii:labels",
        "--mix additive",
    ] {
        assert!(command.contains(part), "{part}: {command}");
    }
    let still = picture(&b.frame_bytes().await, dir.path(), "still.png");
    assert_eq!(run_shown(&b, dir.path()).await, still, "the start");

    // The second channel's panel: an opaque point in its editor.
    b.eval("window.volrayView.select(1); return 0;").await;
    let legend = b.text("tf-of").await;
    assert!(legend.contains("channel 1"), "{legend}");
    b.click_at("#tf", -40.0, -60.0).await;
    b.wait_still().await;
    let edited = picture(&b.frame_bytes().await, dir.path(), "edited.png");
    assert_ne!(edited, still, "the edit did not change the image");
    let state = b.eval("return window.volrayView.state();").await;
    assert!(
        state["opacity"].is_null(),
        "the first channel's look is untouched"
    );
    assert!(state["layers"][0]["opacity"].is_array(), "{state}");
    assert_eq!(run_shown(&b, dir.path()).await, edited, "the edit");

    // One colour for it, and the label volume hidden.
    b.eval("window.volrayView.setState({}); return 0;").await;
    b.eval(
        "const s = window.volrayView.state(); s.layers[0].colormap = '#ffaa00'; \
         s.layers[1].visible = false; window.volrayView.setState({layers: s.layers}); return 0;",
    )
    .await;
    b.wait_still().await;
    let recoloured = picture(&b.frame_bytes().await, dir.path(), "recoloured.png");
    assert_ne!(recoloured, edited);
    let command = b.text("command").await;
    assert!(command.contains("labels,hidden"), "{command}");
    assert_eq!(
        run_shown(&b, dir.path()).await,
        recoloured,
        "hidden and recoloured"
    );

    // A state for a volume the viewer does not show is refused in the page.
    b.eval("window.volrayView.sendState({layers: []}); return 0;")
        .await;
    b.wait_for("document.body.dataset.state === 'error'").await;
    let error = b.text("error").await;
    assert!(
        error.contains("describes 0 volume(s) beside the first"),
        "{error}"
    );
    b.close().await;
}

#[tokio::test(flavor = "current_thread")]
async fn a_time_axis_has_a_slider_whose_time_point_is_the_commands_frame() {
    if !browser::available() {
        return;
    }
    use common::nifti::{ball, nifti};
    let dir = tempfile::tempdir().unwrap();
    let series = nifti(
        dir.path(),
        "series.nii",
        &[ball(6.0), ball(12.0), ball(17.0)],
    );
    let Some((_viewer, b)) = open(&[&series, "--frames", "all", "--size", "64"]).await else {
        return;
    };
    let hidden = b
        .eval("return document.getElementById('time-box').hidden;")
        .await;
    assert_eq!(hidden, false, "the time slider shows");
    let max = b.eval("return document.getElementById('time').max;").await;
    assert_eq!(max, "2");
    assert!(b.text("command").await.contains("--frame 0"));
    let first = picture(&b.frame_bytes().await, dir.path(), "first.png");
    b.eval("window.volrayView.setState({time: 2}); return 0;")
        .await;
    b.wait_still().await;
    let last = picture(&b.frame_bytes().await, dir.path(), "last.png");
    assert_ne!(last, first, "time point 2 is another picture");
    let command = b.text("command").await;
    assert!(command.contains("--frame 2"), "{command}");
    assert_eq!(run_shown(&b, dir.path()).await, last);
    // Back to the first time point: the first picture again.
    b.eval("window.volrayView.setState({time: 0}); return 0;")
        .await;
    b.wait_still().await;
    assert_eq!(
        picture(&b.frame_bytes().await, dir.path(), "again.png"),
        first
    );
    // A time point beyond the file's is refused in the page.
    b.eval("window.volrayView.sendState({time: 3}); return 0;")
        .await;
    b.wait_for("document.body.dataset.state === 'error'").await;
    assert!(b.text("error").await.contains("time point 3 is not served"));
    b.close().await;
}

#[tokio::test(flavor = "current_thread")]
async fn without_a_size_the_frame_fills_the_window_and_follows_it() {
    // No --size: the page sizes the frame to its viewport.
    let Some((_viewer, b)) = open(&["blobs:32"]).await else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let fits = r#"
        const v = document.getElementById('viewport').getBoundingClientRect();
        const f = document.getElementById('frame').getBoundingClientRect();
        const s = window.volrayView.state();
        const k = window.devicePixelRatio || 1;
        return [s.width, s.height, Math.round(v.width * k), Math.round(v.height * k),
                f.width * f.height, (window.innerWidth - (document.body.classList.contains('panel-hidden') ? 0 : document.getElementById('panel').offsetWidth))
                  * (window.innerHeight - document.querySelector('header').offsetHeight)];
    "#;
    let sizes = |v: serde_json::Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let first = sizes(b.eval(fits).await);
    assert_eq!((first[0], first[1]), (first[2], first[3]), "{first:?}");
    assert!(first[4] >= 0.85 * first[5], "the frame's area: {first:?}");
    let still = picture(&b.frame_bytes().await, dir.path(), "still.png");
    assert_eq!(
        (still.width as f64, still.height as f64),
        (first[0], first[1])
    );
    let command = b.text("command").await;
    let size = format!("--size {}x{}", first[0], first[1]);
    assert!(command.contains(&size), "{command}");
    assert_eq!(
        run_shown(&b, dir.path()).await,
        still,
        "the command's frame"
    );

    // Hiding the controls gives the frame their room.
    b.click("#panel-toggle").await;
    b.wait_for(&format!(
        "window.volrayView.state().width > {} && document.body.dataset.state === 'still'",
        first[0] + 300.0
    ))
    .await;
    let wide = sizes(b.eval(fits).await);
    assert_eq!((wide[0], wide[1]), (wide[2], wide[3]), "{wide:?}");
    assert!(wide[4] >= 0.85 * wide[5], "{wide:?}");

    // A smaller window: the frame follows.
    b.client.set_window_size(800, 600).await.unwrap();
    b.wait_for(&format!(
        "window.volrayView.state().width < {} && document.body.dataset.state === 'still'",
        wide[0] - 100.0
    ))
    .await;
    let small = sizes(b.eval(fits).await);
    assert_eq!((small[0], small[1]), (small[2], small[3]), "{small:?}");

    // The views from each side: buttons and keys.
    b.click("#toolbar [data-view='+z']").await;
    b.wait_still().await;
    let command = b.text("command").await;
    assert!(
        command.contains("--azimuth 0") && command.contains("--elevation 90"),
        "{command}"
    );
    let above = picture(&b.frame_bytes().await, dir.path(), "above.png");
    b.eval("document.dispatchEvent(new KeyboardEvent('keydown', {key: '3'})); return 0;")
        .await;
    b.wait_for(
        "window.volrayView.state().azimuth === 90 && window.volrayView.state().elevation === 0",
    )
    .await;
    b.wait_still().await;
    let side = picture(&b.frame_bytes().await, dir.path(), "side.png");
    assert_ne!(side, above, "another view");
    assert_eq!(run_shown(&b, dir.path()).await, side, "the command's frame");
    b.close().await;
}

#[tokio::test(flavor = "current_thread")]
async fn the_crop_clip_and_lighting_controls_change_the_frame_and_the_command_is_it() {
    let Some((_viewer, b)) = open(&["blobs:32", "--size", "96"]).await else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let start = picture(&b.frame_bytes().await, dir.path(), "start.png");
    // Sets a control's value as a user would, and lets it tell the page.
    let set = |id: &'static str, value: &'static str| {
        let b = &b;
        async move {
            b.eval(&format!(
                "const el = document.getElementById('{id}'); el.value = '{value}'; \
                 el.dispatchEvent(new Event('change')); return 0;"
            ))
            .await;
        }
    };

    // A crop box: its x from the middle of the box.
    b.click("#crop-on").await;
    set("crop-x0", "0.5").await;
    b.wait_still().await;
    let cropped = picture(&b.frame_bytes().await, dir.path(), "cropped.png");
    assert_ne!(cropped, start, "the crop changed nothing");
    let command = b.text("command").await;
    assert!(command.contains("--crop "), "{command}");
    assert_eq!(run_shown(&b, dir.path()).await, cropped, "crop");
    b.click("#crop-on").await;

    // A clip plane across z, keeping the low side.
    set("clip-axis", "z").await;
    b.click("#clip-flip").await;
    b.wait_still().await;
    let state = b.eval("return window.volrayView.state();").await;
    assert_eq!(state["crop"], serde_json::Value::Null, "the crop is off");
    assert_eq!(
        state["clip"][0][1],
        serde_json::json!([0, 0, -1]),
        "{state}"
    );
    let clipped = picture(&b.frame_bytes().await, dir.path(), "clipped.png");
    assert_ne!(clipped, start);
    assert_eq!(run_shown(&b, dir.path()).await, clipped, "clip");
    set("clip-axis", "").await;

    // The lighting: no ambient, a light from +y.
    set("l-ambient", "0").await;
    b.click("#headlight").await;
    set("l-azimuth", "90").await;
    b.wait_still().await;
    let command = b.text("command").await;
    assert!(
        command.contains("--ambient 0 ") && command.contains("--light "),
        "{command}"
    );
    assert!(
        !command.contains("--clip"),
        "the clip plane is off: {command}"
    );
    let lit = picture(&b.frame_bytes().await, dir.path(), "lit.png");
    assert_ne!(lit, start);
    assert_eq!(run_shown(&b, dir.path()).await, lit, "lighting");

    // The depth cues: shadows from that light, then ambient occlusion of
    // radius 3 with more ambient light to show it.
    b.click("#shadows").await;
    b.wait_still().await;
    let command = b.text("command").await;
    assert!(command.contains("--shadows"), "{command}");
    let shadowed = picture(&b.frame_bytes().await, dir.path(), "shadowed.png");
    assert_ne!(shadowed, lit, "the shadows changed nothing");
    assert_eq!(run_shown(&b, dir.path()).await, shadowed, "shadows");
    set("l-ambient", "0.6").await;
    set("ao-radius", "3").await;
    b.click("#ao").await;
    b.wait_still().await;
    let command = b.text("command").await;
    assert!(command.contains("--ambient-occlusion 3"), "{command}");
    let occluded = picture(&b.frame_bytes().await, dir.path(), "occluded.png");
    assert_eq!(
        run_shown(&b, dir.path()).await,
        occluded,
        "ambient occlusion"
    );
    // Unlit, the shadows go and the ambient occlusion stays.
    b.click("#shading").await;
    b.wait_still().await;
    let command = b.text("command").await;
    assert!(
        !command.contains("--shadows") && command.contains("--ambient-occlusion 3"),
        "{command}"
    );
    let disabled = "return document.getElementById('shadows').disabled;";
    assert_eq!(b.eval(disabled).await, serde_json::json!(true));
    b.close().await;
}

#[tokio::test(flavor = "current_thread")]
async fn the_pointer_probes_the_world_point_and_value_under_it() {
    // sphere:32: a field over the world box [−1, 1]³ (spacing 2/31),
    // seen from +x; the centre ray runs along the x axis.
    let Some((_viewer, b)) = open(&["sphere:32", "--size", "96"]).await else {
        return;
    };
    b.hover("#frame", (0.0, 0.0)).await;
    b.wait_for("document.getElementById('probe').textContent.includes('value')")
        .await;
    let text = b.text("probe").await;
    // "(x, y, z) · voxel (i, j, k) · value v": on the x axis, in front.
    let numbers: Vec<f64> = text
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e'))
        .filter_map(|w| w.parse().ok())
        .collect();
    let [x, y, z, i, j, k, value] = numbers[..] else {
        panic!("{text}")
    };
    assert!(x > 0.0 && x <= 1.0, "in front of the centre: {text}");
    assert!(y.abs() < 0.05 && z.abs() < 0.05, "on the axis: {text}");
    let voxel = |w: f64| (w + 1.0) * 31.0 / 2.0;
    assert!((voxel(x) - i).abs() < 0.06, "{text}");
    assert!(
        (voxel(y) - j).abs() < 0.06 && (voxel(z) - k).abs() < 0.06,
        "{text}"
    );
    assert!(value > 0.0 && value <= 1.0, "{text}");
    // Off the frame: the probe clears.
    b.hover("#viewport", (-200.0, 0.0)).await;
    b.wait_for("document.getElementById('probe').textContent === ''")
        .await;
    b.close().await;
}

#[tokio::test(flavor = "current_thread")]
async fn the_figure_controls_draw_what_render_draws_into_the_frame() {
    let Some((_viewer, b)) = open(&["sphere:32", "--size", "160", "--colormap", "viridis"]).await
    else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let bare = picture(&b.frame_bytes().await, dir.path(), "bare.png");
    for id in ["f-colorbar", "f-scale", "f-axes", "f-outline"] {
        b.click(&format!("#{id}")).await;
        b.wait_still().await;
    }
    b.eval(
        "const el = document.getElementById('f-title'); el.value = 'A sphere'; \
         el.dispatchEvent(new Event('change')); return 0;",
    )
    .await;
    b.wait_still().await;
    let command = b.text("command").await;
    for part in [
        "--colorbar right",
        "--scale-bar",
        "--axes",
        "--outline",
        "--title 'A sphere'",
    ] {
        assert!(command.contains(part), "{part}: {command}");
    }
    let figure = picture(&b.frame_bytes().await, dir.path(), "figure.png");
    assert_ne!(figure, bare, "nothing was drawn");
    assert_eq!(
        run_shown(&b, dir.path()).await,
        figure,
        "the command's figure"
    );
    // A draft is annotated too, at its size.
    b.eval("window.volrayView.sendState({azimuth: 20}, 'draft'); return 0;")
        .await;
    b.wait_for("window.volrayView.header().quality === 'draft'")
        .await;
    b.close().await;
}
