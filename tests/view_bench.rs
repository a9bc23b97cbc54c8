//! The viewer's goals, measured in a real browser (ignored by `cargo
//! test`; timings are not assertions). Run on a quiet machine:
//!
//! ```sh
//! cargo test --release --test view_bench -- --ignored --nocapture
//! ```
//!
//! `volray view fractal:129 --threads 2` (480² frames) in headless
//! Chromium driven over WebDriver with real pointer events. The page's
//! hooks are timestamped inside the page (a MutationObserver on
//! `data-frames` and `data-state`, listeners on the pointer events), so
//! the WebDriver round trips are not counted:
//!
//! - frames/s during a continuous drag: frames shown between the drag's
//!   pointerdown and pointerup, over that time (3 s, a move every 16 ms);
//! - mouse-up to full-quality frame: from a drag's pointerup to
//!   `data-state = "still"`, over 15 drags (median);
//! - TF edit to new frame: from the pointerdown of a click that adds an
//!   opacity point to the next frame shown, over 15 clicks (median);
//! - a burst of 1,000 requests to the full frame of the last, and the
//!   server's resident memory before and after.

#[path = "view_support/browser.rs"]
mod browser;
#[path = "view_support/viewer.rs"]
mod viewer;

use browser::Browser;
use serde_json::Value;
use std::time::Duration;
use viewer::Viewer;

/// Timestamps the page's hooks and pointer events, in milliseconds.
const INSTRUMENT: &str = r#"
    window.bench = [];
    const log = (what) => window.bench.push([what, performance.now()]);
    new MutationObserver((changes) => {
        for (const c of changes) {
            if (c.attributeName === "data-frames") {
                log("frame");
                const h = window.volrayView.header();
                if (h.quality === "draft") window.bench.push(["draft_ms", h.render_ms, h.encode_ms]);
            }
            if (c.attributeName === "data-state" && document.body.dataset.state === "still") log("still");
        }
    }).observe(document.body, { attributes: true });
    for (const id of ["viewport", "tf"]) {
        for (const kind of ["pointerdown", "pointerup"]) {
            document.getElementById(id).addEventListener(kind, () => log(id + ":" + kind), { capture: true });
        }
    }
    return true;
"#;

/// The events logged since the last call.
async fn events(b: &Browser) -> Vec<(String, f64)> {
    let v = b
        .eval("const e = window.bench; window.bench = []; return e;")
        .await;
    let Value::Array(list) = v else { panic!("{v}") };
    list.iter()
        .map(|e| (e[0].as_str().unwrap().to_string(), e[1].as_f64().unwrap()))
        .collect()
}

/// The time of the first event named `what` at or after `from`.
fn first(events: &[(String, f64)], what: &str, from: f64) -> Option<f64> {
    events
        .iter()
        .find(|(name, t)| name == what && *t >= from)
        .map(|e| e.1)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

fn summary(name: &str, v: &[f64]) {
    let mut sorted = v.to_vec();
    sorted.sort_by(f64::total_cmp);
    println!(
        "{name}: median {:.1} ms (min {:.1}, max {:.1}, n = {})",
        median(v.to_vec()),
        sorted[0],
        sorted[sorted.len() - 1],
        v.len()
    );
}

/// Resident memory of `pid`, in MiB.
fn rss_mib(pid: u32) -> f64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let kb: f64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap();
    kb / 1024.0
}

#[tokio::test(flavor = "current_thread")]
#[ignore = "a benchmark: run on a quiet machine with --ignored --nocapture"]
async fn viewer_goals_for_fractal_129_at_480() {
    if !browser::available() {
        return;
    }
    let volume = std::env::var("VOLRAY_VIEW_BENCH_VOLUME").unwrap_or("fractal:129".into());
    let viewer = Viewer::start(&[&volume, "--threads", "2", "--colormap", "magma"]);
    let b = Browser::start().await;
    b.client.goto(&viewer.url).await.unwrap();
    b.wait_still().await;
    b.eval(INSTRUMENT).await;
    // Warm up: a drag and a TF edit.
    b.drag("#frame", (0.0, 0.0), (40.0, 10.0), 10).await;
    b.wait_still().await;
    b.click_at("#tf", 0.0, -40.0).await;
    b.wait_still().await;
    events(&b).await;

    // A continuous drag of 3 s.
    b.drag("#frame", (-150.0, 0.0), (300.0, 60.0), 188).await;
    b.wait_still().await;
    let e = events(&b).await;
    let down = first(&e, "viewport:pointerdown", 0.0).unwrap();
    let up = first(&e, "viewport:pointerup", down).unwrap();
    let shown = e
        .iter()
        .filter(|(n, t)| n == "frame" && *t > down && *t <= up)
        .count();
    let draft = b.eval("return window.volrayView.header();").await;
    let fps = shown as f64 / ((up - down) / 1000.0);
    let drafts: Vec<f64> = e
        .iter()
        .filter(|(n, _)| n == "draft_ms")
        .map(|(_, t)| *t)
        .collect();
    summary("  a draft frame's rendering (240², on the server)", &drafts);
    println!(
        "drag: {shown} frames in {:.0} ms: {fps:.1} frames/s (a full frame renders in {} ms)",
        up - down,
        draft["render_ms"]
    );

    // Mouse-up to the full-quality frame.
    let mut still = Vec::new();
    let (mut render, mut encode) = (Vec::new(), Vec::new());
    for i in 0..15 {
        let dx = if i % 2 == 0 { 60.0 } else { -60.0 };
        b.drag("#frame", (0.0, 0.0), (dx, 20.0), 10).await;
        b.wait_still().await;
        let e = events(&b).await;
        let up = first(&e, "viewport:pointerup", 0.0).unwrap();
        still.push(first(&e, "still", up).unwrap() - up);
        let header = b.eval("return window.volrayView.header();").await;
        render.push(header["render_ms"].as_f64().unwrap());
        encode.push(header["encode_ms"].as_f64().unwrap());
    }
    summary("mouse-up to full-quality frame", &still);
    summary("  of which rendering the full frame", &render);
    summary("  of which encoding its PNG", &encode);

    // TF edit to the next frame shown (and to the still frame).
    let mut edit = Vec::new();
    let mut edit_still = Vec::new();
    for i in 0..15 {
        let x = -140.0 + 20.0 * i as f64;
        let y = if i % 2 == 0 { -50.0 } else { 10.0 };
        b.click_at("#tf", x, y).await;
        b.wait_still().await;
        let e = events(&b).await;
        let down = first(&e, "tf:pointerdown", 0.0).unwrap();
        edit.push(first(&e, "frame", down).unwrap() - down);
        edit_still.push(first(&e, "still", down).unwrap() - down);
        let header = b.eval("return window.volrayView.header();").await;
        render.push(header["render_ms"].as_f64().unwrap());
    }
    summary("TF edit to new frame", &edit);
    summary("TF edit to full-quality frame", &edit_still);
    summary(
        "  of which rendering (classification included)",
        &render[15..],
    );

    // A burst of 1,000 requests, then the full frame of the last.
    let rss_before = rss_mib(viewer.pid());
    let frames_before = viewer.status()["frames"].as_u64().unwrap();
    let t = b
        .eval(
            r#"const v = window.volrayView; const t = performance.now();
               for (let i = 0; i < 1000; i++) v.sendState({azimuth: i / 10}, "draft");
               v.sendState({azimuth: 123.4}, "full"); return t;"#,
        )
        .await
        .as_f64()
        .unwrap();
    b.wait_still().await;
    let e = events(&b).await;
    let burst = first(&e, "still", t).unwrap() - t;
    let rendered = viewer.status()["frames"].as_u64().unwrap() - frames_before;
    tokio::time::sleep(Duration::from_millis(200)).await;
    println!(
        "burst of 1,000 + 1: full frame after {burst:.0} ms, {rendered} frames rendered; server RSS {rss_before:.0} MiB before, {:.0} MiB after",
        rss_mib(viewer.pid())
    );
    b.close().await;
}

/// CPU seconds `pid` has used (user and system).
fn cpu_seconds(pid: u32) -> f64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
    // The fields after the command's closing parenthesis; utime and stime
    // are the 14th and 15th of the line, in clock ticks (100 a second).
    let rest = &stat[stat.rfind(')').unwrap() + 2..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = fields[11].parse::<f64>().unwrap() + fields[12].parse::<f64>().unwrap();
    ticks / 100.0
}

/// A 4096² frame at step 0.001, and an ordinary one at `azimuth`.
const SLOW: &str =
    "window.volrayView.sendState({width: 4096, height: 4096, step: 0.001}); return true;";

/// Sends the ordinary view at `azimuth`, returning the page's time.
async fn send_ordinary(b: &Browser, azimuth: u32) -> f64 {
    b.eval(&format!(
        "const t = performance.now(); window.volrayView.sendState({{width: 480, height: 480, step: 1, azimuth: {azimuth}}}); return t;"
    ))
    .await
    .as_f64()
    .unwrap()
}

#[tokio::test(flavor = "current_thread")]
#[ignore = "a benchmark: run on a quiet machine with --ignored --nocapture"]
async fn a_slow_frame_gives_way_to_an_ordinary_one_and_to_its_tab_closing() {
    if !browser::available() {
        return;
    }
    let volume = std::env::var("VOLRAY_VIEW_BENCH_VOLUME").unwrap_or("fractal:129".into());
    let viewer = Viewer::start(&[&volume, "--threads", "2", "--colormap", "magma"]);
    let b = Browser::start().await;
    let first_tab = b.client.window().await.unwrap();
    b.client.goto(&viewer.url).await.unwrap();
    b.wait_still().await;
    b.eval(INSTRUMENT).await;
    events(&b).await;

    // A 4096², step 0.001 frame, well under way, then an ordinary 480²
    // full frame: from the ordinary request to its frame shown.
    let mut ordinary = Vec::new();
    let mut render = Vec::new();
    for i in 0..10 {
        b.eval(SLOW).await;
        viewer.wait_status(browser::PATIENCE, |s| s["rendering"] == 1);
        tokio::time::sleep(Duration::from_millis(500)).await;
        let t = send_ordinary(&b, 10 * i).await;
        b.wait_still().await;
        let e = events(&b).await;
        ordinary.push(first(&e, "still", t).unwrap() - t);
        let header = b.eval("return window.volrayView.header();").await;
        render.push(header["render_ms"].as_f64().unwrap());
    }
    summary(
        "a 4096² step-0.001 frame, then an ordinary one: its frame shown after",
        &ordinary,
    );
    summary("  of which rendering the ordinary frame", &render);

    // A tab closed during a slow frame: from the close to no frame being
    // rendered (the status polled every 5 ms; the WebDriver round trip of
    // the close is counted), and the server's CPU time in the second
    // after.
    let mut idle = Vec::new();
    let mut cpu_after = Vec::new();
    for _ in 0..10 {
        let tab = b.client.new_window(true).await.unwrap().handle;
        b.client.switch_to_window(tab).await.unwrap();
        b.client.goto(&viewer.url).await.unwrap();
        b.wait_still().await;
        b.eval(SLOW).await;
        viewer.wait_status(browser::PATIENCE, |s| s["rendering"] == 1);
        tokio::time::sleep(Duration::from_millis(500)).await;
        let start = std::time::Instant::now();
        b.client.close_window().await.unwrap();
        loop {
            if viewer.status()["rendering"] == 0 {
                break;
            }
            assert!(
                start.elapsed() < browser::PATIENCE,
                "the frame was not stopped"
            );
            std::thread::sleep(Duration::from_millis(5));
        }
        idle.push(start.elapsed().as_secs_f64() * 1e3);
        let cpu = cpu_seconds(viewer.pid());
        tokio::time::sleep(Duration::from_secs(1)).await;
        cpu_after.push((cpu_seconds(viewer.pid()) - cpu) * 1e3);
        b.client.switch_to_window(first_tab.clone()).await.unwrap();
    }
    summary(
        "a tab closed during a slow frame: no frame rendering after",
        &idle,
    );
    summary(
        "  the server's CPU time in the second after (ms)",
        &cpu_after,
    );
    let status = viewer.status();
    println!("status at the end: {status}");
    b.close().await;
}

/// Drags of `moves` moves over the frame, `dx` apart, timed in the page:
/// (frames shown during the drag per second, mouse-up to the first frame
/// shown, mouse-up to the full-quality frame), in milliseconds.
async fn timed_drag(b: &Browser, moves: u32, dx: f64) -> (f64, f64, f64) {
    b.drag(
        "#frame",
        (-dx * moves as f64 / 2.0, 0.0),
        (dx * moves as f64, 20.0),
        moves,
    )
    .await;
    b.wait_still().await;
    let e = events(b).await;
    if std::env::var("VOLRAY_VIEW_BENCH_DEBUG").is_ok() {
        println!("{e:?}");
    }
    let down = first(&e, "viewport:pointerdown", 0.0).unwrap();
    let up = first(&e, "viewport:pointerup", down).unwrap();
    let shown = (e.iter())
        .filter(|(n, t)| n == "frame" && *t > down && *t <= up)
        .count();
    let next = first(&e, "frame", up).unwrap_or(f64::NAN) - up;
    let still = first(&e, "still", up).unwrap() - up;
    (shown as f64 / ((up - down) / 1000.0), next, still)
}

/// Issue 27's goals in a 1280×800 viewport, the frame filling the window
/// (no --size): `VOLRAY_VIEW_BENCH_ARGS` (default `fractal:257 --colormap
/// magma`, as docs/viewer.md measures it), e.g.
/// `"/tmp/ct512.raw --dims 512,512,512 --dtype i16 --preset ct-bone"`.
#[tokio::test(flavor = "current_thread")]
#[ignore = "a benchmark: run on a quiet machine with --ignored --nocapture"]
async fn the_application_at_1280_by_800() {
    if !browser::available() {
        return;
    }
    let args =
        std::env::var("VOLRAY_VIEW_BENCH_ARGS").unwrap_or("fractal:257 --colormap magma".into());
    let mut words: Vec<&str> = args.split_whitespace().collect();
    words.extend(["--threads", "2"]);
    let viewer = Viewer::start(&words);
    let b = Browser::start().await;
    // A 1280×800 viewport: the window less what the browser keeps of it.
    b.client.set_window_size(1280, 800).await.unwrap();
    let inner = b
        .eval("return [window.innerWidth, window.innerHeight];")
        .await;
    let (w, h) = (inner[0].as_u64().unwrap(), inner[1].as_u64().unwrap());
    b.client
        .set_window_size((2560 - w) as u32, (1600 - h) as u32)
        .await
        .unwrap();
    b.client.goto(&viewer.url).await.unwrap();
    b.wait_still().await;
    b.eval(INSTRUMENT).await;
    let geometry = b
        .eval(
            r#"const f = document.getElementById('frame').getBoundingClientRect();
               const free = (window.innerWidth - document.getElementById('panel').offsetWidth)
                 * (window.innerHeight - document.querySelector('header').offsetHeight);
               const s = window.volrayView.state();
               return [window.innerWidth, window.innerHeight, s.width, s.height, f.width * f.height / free];"#,
        )
        .await;
    println!("viewport, frame and share of the free area: {geometry}");
    // Warm up.
    timed_drag(&b, 10, 6.0).await;
    events(&b).await;

    let mut fps = Vec::new();
    let mut first_frame = Vec::new();
    let mut still = Vec::new();
    let mut scales = Vec::new();
    for _ in 0..5 {
        let (f, n, s) = timed_drag(&b, 120, 3.0).await;
        fps.push(f);
        first_frame.push(n);
        still.push(s);
        scales.push(
            b.eval("return window.volrayView.draftScale();")
                .await
                .as_f64()
                .unwrap(),
        );
    }
    let header = b.eval("return window.volrayView.header();").await;
    println!(
        "drags of 120 moves: {:?} frames/s (median {:.1}); draft scale after each: {scales:?}",
        fps.iter()
            .map(|f| (f * 10.0).round() / 10.0)
            .collect::<Vec<_>>(),
        median(fps.clone())
    );
    summary("mouse-up to the first frame after it", &first_frame);
    summary("mouse-up to the full-size still", &still);
    println!("the last still: {} ms to render", header["render_ms"]);

    // A 4096² frame at step 0.01 under way, then the view moves again
    // (a draft of the window's view, as a drag's first move sends): from
    // that request to its frame shown.
    let mut waits = Vec::new();
    for i in 0..5 {
        b.eval(
            "window.normal = window.volrayView.state(); \
             window.volrayView.sendState({width: 4096, height: 4096, step: 0.01}); return 0;",
        )
        .await;
        viewer.wait_status(browser::PATIENCE, |s| s["rendering"] == 1);
        tokio::time::sleep(Duration::from_millis(300)).await;
        events(&b).await;
        let t = b
            .eval(&format!(
                "const n = window.normal; const t = performance.now(); \
                 window.volrayView.sendState({{width: n.width, height: n.height, step: n.step, azimuth: {}}}, 'draft'); \
                 return t;",
                10 * i
            ))
            .await
            .as_f64()
            .unwrap();
        tokio::time::sleep(Duration::from_millis(1500)).await;
        let e = events(&b).await;
        // No frame within the 1.5 s waited: a miss, counted as infinite.
        waits.push(first(&e, "frame", t).map_or(f64::INFINITY, |f| f - t));
        b.eval("window.volrayView.sendState({}); return 0;").await;
        b.wait_still().await;
    }
    summary(
        "a 4096² step-0.01 frame under way, then a draft of the view: its frame",
        &waits,
    );
    b.close().await;
}

/// Screenshots of the page at three window sizes (docs/viewer.md), into
/// `VOLRAY_VIEW_SCREENSHOTS` (a folder), of `VOLRAY_VIEW_BENCH_ARGS`.
#[tokio::test(flavor = "current_thread")]
#[ignore = "writes the docs' screenshots: run with --ignored"]
async fn screenshots_at_three_window_sizes() {
    let Ok(dir) = std::env::var("VOLRAY_VIEW_SCREENSHOTS") else {
        return;
    };
    if !browser::available() {
        return;
    }
    let args = std::env::var("VOLRAY_VIEW_BENCH_ARGS").unwrap_or("fractal:129".into());
    let words: Vec<&str> = args.split_whitespace().collect();
    let viewer = Viewer::start(&words);
    let b = Browser::start().await;
    for (w, h) in [(1024, 640), (1440, 900), (1920, 1080)] {
        b.client.set_window_size(w, h).await.unwrap();
        let inner = b
            .eval("return [window.innerWidth, window.innerHeight];")
            .await;
        let (iw, ih) = (inner[0].as_u64().unwrap(), inner[1].as_u64().unwrap());
        b.client
            .set_window_size(2 * w - iw as u32, 2 * h - ih as u32)
            .await
            .unwrap();
        b.client.goto(&viewer.url).await.unwrap();
        b.wait_still().await;
        // The probe, over the middle of the frame.
        b.hover("#frame", (20.0, -20.0)).await;
        b.wait_for("document.getElementById('probe').textContent !== ''")
            .await;
        b.wait_still().await;
        let png = b.client.screenshot().await.unwrap();
        std::fs::write(format!("{dir}/viewer-{w}x{h}.png"), png).unwrap();
    }
    b.close().await;
}
