//! `chart --plan/--from` and `gallery --plan/--from`: work written as
//! independent command lines, run one by one, and assembled, gives what
//! the command gives in one process.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn pinhole(args: &[&str], cache: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pinhole")).args(args).env("PINHOLE_CACHE_DIR", cache).output().expect("run pinhole")
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinhole-plans-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn ok(out: &Output) -> String {
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "{err}");
    err
}

/// Runs every line of `plan/jobs.txt` through the shell, one after another.
fn run_jobs(plan: &Path, cache: &Path) -> Vec<String> {
    let lines: Vec<String> = std::fs::read_to_string(plan.join("jobs.txt")).unwrap().lines().map(String::from).collect();
    for line in &lines {
        let out = Command::new("sh").args(["-c", line]).env("PINHOLE_CACHE_DIR", cache).output().unwrap();
        assert!(out.status.success(), "{line}: {}", String::from_utf8_lossy(&out.stderr));
    }
    lines
}

fn assemble(plan: &Path, cache: &Path) -> Output {
    let line = std::fs::read_to_string(plan.join("assemble.txt")).unwrap();
    Command::new("sh").args(["-c", line.trim()]).env("PINHOLE_CACHE_DIR", cache).output().unwrap()
}

/// The CSV's rows without the timing column (`method,ms,rel_rmse,flip`).
fn rows_without_times(csv: &Path) -> Vec<String> {
    std::fs::read_to_string(csv)
        .unwrap()
        .lines()
        .map(|l| {
            let mut f: Vec<&str> = l.rsplitn(4, ',').collect();
            f.reverse();
            format!("{},{},{}", f[0], f[2], f[3])
        })
        .collect()
}

#[test]
fn a_planned_chart_has_the_rows_of_a_chart_measured_in_one_process() {
    let d = dir("chart");
    let cache = d.join("cache");
    // spheres: its glossy lobes bring the model sweep (--glossy-model jobs);
    // 64 reference samples render as two sample ranges.
    let common = ["spheres", "--width", "32", "--height", "24", "--reference-spp", "64"];
    let direct = d.join("direct.png");
    let mut args = vec!["chart", "-o", direct.to_str().unwrap()];
    args.extend(common);
    ok(&pinhole(&args, &cache));

    let plan = d.join("plan");
    let planned = d.join("planned.png");
    let mut args = vec!["chart", "-o", planned.to_str().unwrap(), "--plan", plan.to_str().unwrap()];
    args.extend(common);
    ok(&pinhole(&args, &d.join("cache-plan")));
    assert!(!planned.exists(), "--plan measures nothing");
    let lines = run_jobs(&plan, &d.join("cache-plan"));
    let reference_jobs = lines.iter().filter(|l| l.contains(" --sample-range ")).count();
    assert_eq!(reference_jobs, 2, "{lines:?}");
    assert!(lines.iter().any(|l| l.contains("--glossy-model ggx")), "{lines:?}");
    assert!(lines.iter().all(|l| l.contains(" render ")), "{lines:?}");

    // Missing results are named with the line that makes them.
    let config = plan.join("config-000.exr");
    let kept = std::fs::read(&config).unwrap();
    std::fs::remove_file(&config).unwrap();
    let out = assemble(&plan, &d.join("cache-plan"));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("config-000.exr") && err.contains("run line 3 of"), "{err}");
    assert!(!planned.exists());
    std::fs::write(&config, kept).unwrap();

    // The reference's two ranges merged are the one-process chart's
    // reference (which it cached) to the bit: both add the same ranges.
    let merged = d.join("reference.exr");
    let refs: Vec<String> = (0..2).map(|k| plan.join(format!("reference-{k:03}.exr")).to_string_lossy().into_owned()).collect();
    ok(&pinhole(&["merge", &refs[0], &refs[1], "-o", merged.to_str().unwrap()], &cache));
    let cached = std::fs::read_dir(&cache).unwrap().next().unwrap().unwrap().path();
    let bits = |p: &Path| pinhole::image_io::load_image(p).unwrap().pixels.iter().map(|c| [c.x.to_bits(), c.y.to_bits(), c.z.to_bits()]).collect::<Vec<_>>();
    assert!(bits(&merged) == bits(&cached), "the planned reference differs from the one-process chart's");

    ok(&assemble(&plan, &d.join("cache-plan")));
    let (a, b) = (rows_without_times(&direct.with_extension("csv")), rows_without_times(&planned.with_extension("csv")));
    assert!(a.len() > 12, "{a:?}");
    assert_eq!(a, b);
    assert!(image::open(&planned).is_ok());

    // A plan does not go into a folder that already holds files.
    let out = pinhole(&args, &d.join("cache-plan"));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("not empty"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_chart_assembled_with_other_options_than_planned_is_refused() {
    let d = dir("mismatch");
    let plan = d.join("plan");
    let png = d.join("c.png");
    let base = ["chart", "one-triangle", "-o", png.to_str().unwrap(), "--width", "16", "--height", "12", "--reference-spp", "4"];
    let mut args = base.to_vec();
    args.extend(["--plan", plan.to_str().unwrap()]);
    ok(&pinhole(&args, &d));
    run_jobs(&plan, &d);
    let mut args = base.to_vec();
    args.extend(["--from", plan.to_str().unwrap(), "--seed", "7"]);
    let out = pinhole(&args, &d);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("not rendered as this chart plans"), "{err}");
    assert!(!png.exists());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_planned_gallery_is_the_gallery_measured_in_one_process() {
    let d = dir("gallery");
    let direct = d.join("direct");
    ok(&pinhole(&["gallery", "--case", "shadow-acne", "-o", direct.to_str().unwrap()], &d));
    let plan = d.join("plan");
    let planned = d.join("planned");
    ok(&pinhole(&["gallery", "--case", "shadow-acne", "-o", planned.to_str().unwrap(), "--plan", plan.to_str().unwrap()], &d));
    let lines = run_jobs(&plan, &d);
    assert_eq!(lines.len(), 1);
    ok(&assemble(&plan, &d));
    assert_eq!(std::fs::read_to_string(direct.join("gallery.json")).unwrap(), std::fs::read_to_string(planned.join("gallery.json")).unwrap());
    assert_eq!(std::fs::read(direct.join("gallery.png")).unwrap(), std::fs::read(planned.join("gallery.png")).unwrap(), "the same sheet");
    let _ = std::fs::remove_dir_all(&d);
}
