//! End to end on a real Slurm: a one-node cluster started on this machine
//! (scripts/cluster/start_local_slurm.sh), a 4-part render of `cornell-gi`
//! at `--gi path` submitted through scripts/cluster/slurm-render.sh, its
//! merge job awaited, and the merged image compared with a render on one
//! machine; then a chart's plan run through scripts/cluster/slurm-chart.sh.
//! The cluster is stopped at the end, also when the test fails.
//!
//! Needs root and Debian's `slurm-wlm` and `munge`. Where they are missing
//! the test says why and skips; with `PINHOLE_REQUIRE_SLURM=1` (as CI runs
//! it) it fails instead.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

const REQUIRE: &str = "PINHOLE_REQUIRE_SLURM";

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Why Slurm cannot run here, if it cannot.
fn missing() -> Option<String> {
    for tool in ["/usr/sbin/slurmctld", "/usr/sbin/slurmd", "/usr/sbin/munged", "/usr/bin/sbatch"] {
        if !Path::new(tool).exists() {
            return Some(format!("{tool} is not installed (apt-get install slurm-wlm munge)"));
        }
    }
    let uid = Command::new("id").arg("-u").output().ok().map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string());
    (uid.as_deref() != Some("0")).then(|| "the local cluster's daemons are started as root".to_string())
}

/// A running cluster under `dir`, stopped (and its folder removed) when dropped.
struct Cluster {
    dir: PathBuf,
    conf: String,
}

/// Ports of their own, so a cluster the user runs on the defaults is left alone.
const PORTS: [(&str, &str); 3] = [("SLURM_CTLD_PORT", "6927"), ("SLURMD_PORT", "6928"), ("SLURM_SRUN_PORTS", "63101-63400")];

impl Cluster {
    fn start(dir: PathBuf) -> Cluster {
        let out = Command::new(repo().join("scripts/cluster/start_local_slurm.sh"))
            .arg(&dir)
            .env("SLURM_NO_INSTALL", "1")
            .env("SLURM_CPUS", "4")
            .envs(PORTS)
            .output()
            .expect("run start_local_slurm.sh");
        // Built before checking, so that a half-started cluster is stopped too.
        let conf = dir.join("etc/slurm.conf").to_string_lossy().into_owned();
        let cluster = Cluster { dir, conf };
        assert!(out.status.success(), "the cluster did not start: {}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
        cluster
    }

    fn command(&self, program: impl AsRef<std::ffi::OsStr>) -> Command {
        let mut c = Command::new(program);
        c.env("SLURM_CONF", &self.conf);
        c
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = Command::new(repo().join("scripts/cluster/stop_local_slurm.sh")).arg(&self.dir).arg("--purge").envs(PORTS).output();
    }
}

fn bits(path: &Path) -> (u32, u32, Vec<[u32; 3]>) {
    let img = pinhole::image_io::load_image(path).unwrap();
    (img.width, img.height, img.pixels.iter().map(|c| [c.x.to_bits(), c.y.to_bits(), c.z.to_bits()]).collect())
}

#[test]
fn a_split_render_on_slurm_equals_one_machines() {
    if let Some(why) = missing() {
        if std::env::var(REQUIRE).as_deref() == Ok("1") {
            panic!("{REQUIRE}=1 but Slurm cannot run here: {why}");
        }
        eprintln!("skipped: {why}");
        return;
    }
    let work = std::env::temp_dir().join(format!("pinhole-slurm-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&work);
    std::fs::create_dir_all(&work).unwrap();
    let cluster = Cluster::start(work.join("cluster"));
    let pinhole = env!("CARGO_BIN_EXE_pinhole");
    let options = ["--gi", "path", "--spp", "8", "--width", "96", "--height", "72"];

    let merged = work.join("merged.exr");
    let submitted = Instant::now();
    let out = cluster
        .command(repo().join("scripts/cluster/slurm-render.sh"))
        .args(["cornell-gi", merged.to_str().unwrap(), "--parts", "4"])
        .args(options)
        .env("PINHOLE", pinhole)
        .current_dir(&work)
        .output()
        .expect("run slurm-render.sh");
    let said = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "slurm-render.sh failed: {said}{}", String::from_utf8_lossy(&out.stderr));
    let id = |what: &str| said.lines().find_map(|l| l.strip_prefix(what)).map(|s| s.trim().to_string()).unwrap_or_else(|| panic!("no {what}job id in {said:?}"));
    let (render_job, merge_job) = (id("render "), id("merge "));
    assert!(render_job.parse::<u64>().is_ok() && merge_job.parse::<u64>().is_ok(), "{said}");

    // The merge job leaves the queue once it ran (or could not run).
    let deadline = Instant::now() + Duration::from_secs(300);
    loop {
        let q = cluster.command("squeue").args(["-h", "-j", &merge_job]).output().expect("run squeue");
        if q.status.success() && q.stdout.is_empty() {
            break;
        }
        assert!(Instant::now() < deadline, "the merge job {merge_job} was still queued after 300 s");
        std::thread::sleep(Duration::from_millis(250));
    }
    let overhead = submitted.elapsed();
    let parts = merged.with_extension("exr.parts");
    let logs = || {
        std::fs::read_dir(&parts).map(|d| d.flatten().filter(|e| e.path().extension().is_some_and(|x| x == "log")).map(|e| format!("{}: {}", e.path().display(), std::fs::read_to_string(e.path()).unwrap_or_default())).collect::<Vec<_>>().join("\n")).unwrap_or_default()
    };
    assert!(merged.exists(), "the merge job wrote no image; logs:\n{}", logs());
    eprintln!("submission to merged image: {:.1} s", overhead.as_secs_f64());

    let single = work.join("single.exr");
    let out = Command::new(pinhole).args(["render", "cornell-gi", "-o", single.to_str().unwrap()]).args(options).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(bits(&merged) == bits(&single), "the Slurm render differs from the single-machine render");
    let stats: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(merged.with_extension("exr.json")).unwrap()).unwrap();
    assert_eq!(stats["parts"], 4);
    assert_eq!(stats["spp"], 8);

    // A chart's plan through slurm-chart.sh: a job array over its lines and
    // the assembling job after them.
    let plan = work.join("plan");
    let chart = work.join("chart.png");
    let out = Command::new(pinhole)
        .args(["chart", "one-triangle", "-o", chart.to_str().unwrap(), "--width", "16", "--height", "12", "--reference-spp", "4", "--plan", plan.to_str().unwrap()])
        .env("PINHOLE_CACHE_DIR", work.join("cache"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = cluster.command(repo().join("scripts/cluster/slurm-chart.sh")).arg(&plan).current_dir(&work).output().expect("run slurm-chart.sh");
    let said = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "slurm-chart.sh failed: {said}{}", String::from_utf8_lossy(&out.stderr));
    let assemble_job = said.lines().find_map(|l| l.strip_prefix("assemble ")).map(|s| s.trim().to_string()).unwrap_or_else(|| panic!("no assemble job id in {said:?}"));
    let deadline = Instant::now() + Duration::from_secs(300);
    loop {
        let q = cluster.command("squeue").args(["-h", "-j", &assemble_job]).output().expect("run squeue");
        if q.status.success() && q.stdout.is_empty() {
            break;
        }
        assert!(Instant::now() < deadline, "the assemble job {assemble_job} was still queued after 300 s");
        std::thread::sleep(Duration::from_millis(250));
    }
    let csv = std::fs::read_to_string(chart.with_extension("csv")).unwrap_or_else(|e| panic!("no chart CSV ({e}); {}", std::fs::read_to_string(plan.join("assemble.log")).unwrap_or_default()));
    let lines = std::fs::read_to_string(plan.join("jobs.txt")).unwrap().lines().count();
    // One row per configuration: every line but the reference's one range.
    assert_eq!(csv.lines().count() - 1, lines - 1, "{csv}");
    drop(cluster);
    let _ = std::fs::remove_dir_all(&work);
}
