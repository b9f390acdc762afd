//! Runs the vgsel-colmap binary under a wall-clock limit and classifies the outcome, so a hang
//! fails a test (and the fuzzer) instead of blocking it, and a panic is told from an error.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// How a bounded run ended.
#[derive(Debug)]
pub struct Run {
    /// Exit status; None when the watchdog killed it.
    pub code: Option<i32>,
    pub stderr: String,
    pub seconds: f64,
}

impl Run {
    /// What is wrong with this run whatever the input (a hang, a panic, a failure without a
    /// one-line error as the last stderr line), or None.
    pub fn fault(&self) -> Option<String> {
        let err = &self.stderr;
        match self.code {
            None => Some(format!("hang: killed after {:.1} s", self.seconds)),
            Some(101) => Some(format!("panic (exit 101): {err}")),
            _ if err.contains("panicked") => Some(format!("panic: {err}")),
            Some(0) => None,
            Some(code) => {
                let errors = err.lines().filter(|l| l.contains("error")).count();
                let last = err.lines().last().unwrap_or("");
                (errors != 1 || !last.starts_with("vgsel-colmap: error: "))
                    .then(|| format!("exit {code} without a one-line error: {err:?}"))
            }
        }
    }

    pub fn succeeded(&self) -> bool {
        self.code == Some(0)
    }

    /// The error line of a failed run.
    pub fn error_line(&self) -> &str {
        self.stderr.lines().last().unwrap_or("")
    }
}

/// Starts vgsel-colmap with `args` and extra environment variables; stderr goes to `stderr`.
pub fn spawn(args: &[&str], env: &[(&str, &str)], stderr: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_vgsel-colmap"))
        .args(args)
        .envs(env.iter().copied())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(stderr).unwrap())
        .spawn()
        .expect("starting vgsel-colmap")
}

/// Waits for `child` at most `limit`, then kills it.
pub fn wait(mut child: Child, stderr: &Path, limit: Duration) -> Run {
    let start = Instant::now();
    let code = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status.code();
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    Run {
        code,
        stderr: std::fs::read_to_string(stderr).unwrap_or_default(),
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// Runs vgsel-colmap with `args`, killed after `limit`.
pub fn run(args: &[&str], limit: Duration) -> Run {
    let dir = tempfile::tempdir().unwrap();
    let stderr = dir.path().join("stderr");
    wait(spawn(args, &[], &stderr), &stderr, limit)
}
