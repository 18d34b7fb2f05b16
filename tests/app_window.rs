//! A real window under Xvfb with Mesa's software OpenGL: `pinhole --screenshot`
//! opens the viewer, waits for the full-quality frame and saves the window;
//! the viewport region of that screenshot must match `pinhole render` of the
//! same scene and camera (the viewer shows the image 1:1 in that mode).
//! Skipped, with a note, when neither a DISPLAY nor xvfb-run is available.

use std::path::Path;
use std::process::Command;

fn have(cmd: &str) -> bool {
    Command::new("sh").arg("-c").arg(format!("command -v {cmd} >/dev/null")).status().is_ok_and(|s| s.success())
}

/// Runs `pinhole ARGS` in a window: directly with a DISPLAY, else under xvfb-run.
fn run_windowed(args: &[&str]) -> Option<std::process::Output> {
    let exe = env!("CARGO_BIN_EXE_pinhole");
    let mut cmd = if std::env::var_os("DISPLAY").is_some() {
        Command::new(exe)
    } else if have("xvfb-run") {
        let mut c = Command::new("xvfb-run");
        c.args(["-a", "-s", "-screen 0 1280x800x24", exe]);
        c
    } else if std::env::var("PINHOLE_REQUIRE_GL").is_ok_and(|v| v == "1") {
        panic!("PINHOLE_REQUIRE_GL=1 but there is no DISPLAY and no xvfb-run to open a window");
    } else {
        eprintln!("note: app_window skipped: no DISPLAY and no xvfb-run (apt-get install xvfb libgl1-mesa-dri)");
        return None;
    };
    cmd.args(args).env("LIBGL_ALWAYS_SOFTWARE", "1");
    Some(cmd.output().expect("cannot run pinhole"))
}

#[test]
fn screenshot_viewport_matches_pinhole_render() {
    let dir = std::env::temp_dir().join(format!("pinhole-window-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let shot = dir.join("window.png");
    let Some(out) = run_windowed(&["--screenshot", shot.to_str().unwrap(), "one-triangle"]) else { return };
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "pinhole --screenshot failed: {}\n{stdout}", String::from_utf8_lossy(&out.stderr));
    // The viewer prints where the image sits in the window, in pixels.
    let rect: Vec<u32> = stdout
        .lines()
        .find_map(|l| l.strip_prefix("viewport="))
        .expect("no viewport= line")
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let reference = dir.join("render.png");
    let st = Command::new(env!("CARGO_BIN_EXE_pinhole"))
        .args(["render", "one-triangle", "--renderer", "raytrace:bvh", "-o", reference.to_str().unwrap()])
        .status()
        .unwrap();
    assert!(st.success());
    let window = image::open(&shot).unwrap().to_rgb8();
    let render = image::open(&reference).unwrap().to_rgb8();
    assert_eq!((rect[2], rect[3]), render.dimensions(), "the viewer shows the image 1:1");
    let mut bad = 0u32;
    let mut worst = 0i32;
    for (x, y, p) in render.enumerate_pixels() {
        let q = window.get_pixel(rect[0] + x, rect[1] + y);
        let d = (0..3).map(|c| (p[c] as i32 - q[c] as i32).abs()).max().unwrap();
        worst = worst.max(d);
        if d > 2 {
            bad += 1;
        }
    }
    let total = render.width() * render.height();
    assert!(bad * 1000 <= total, "{bad} of {total} pixels differ by more than 2 levels (worst {worst})");
    // The window around the viewport holds the panels: it is not all image.
    assert!(window.width() > render.width() && window.height() > render.height());
    keep_copy(&shot);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Leaves the last screenshot in target/ for a human to look at.
fn keep_copy(shot: &Path) {
    let dest = Path::new(env!("CARGO_MANIFEST_DIR")).join("target").join("app_window.png");
    let _ = std::fs::copy(shot, dest);
}
