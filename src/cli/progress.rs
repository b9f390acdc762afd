//! What the user sees while a command runs: a spinner per stage with its elapsed time when
//! stderr is a terminal, plain timestamped lines with `-v`, nothing otherwise or with
//! `-q` — logs and pipes stay clean, and errors are always the last line.

use indicatif::{ProgressBar, ProgressStyle};
use std::cell::RefCell;
use std::io::IsTerminal;
use std::time::{Duration, Instant};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    Silent,
    Bars,
    Lines,
}

/// Reports the stages of a command on stderr, in the mode chosen by `-q`, `-v` and the terminal.
pub struct Progress {
    mode: Mode,
    started: Instant,
    current: RefCell<Option<ProgressBar>>,
}

impl Progress {
    /// `-q` wins over `-v`; without either, bars only on a terminal.
    pub fn new(quiet: bool, verbose: bool) -> Progress {
        let mode = if quiet {
            Mode::Silent
        } else if verbose {
            Mode::Lines
        } else if std::io::stderr().is_terminal() {
            Mode::Bars
        } else {
            Mode::Silent
        };
        Progress {
            mode,
            started: Instant::now(),
            current: RefCell::new(None),
        }
    }

    /// A new stage: ends the previous spinner and starts one for `name`.
    pub fn stage(&self, name: &str) {
        self.finish();
        match self.mode {
            Mode::Silent => {}
            Mode::Lines => self.line(name),
            Mode::Bars => {
                let bar = ProgressBar::new_spinner().with_message(name.to_string());
                bar.set_style(
                    ProgressStyle::with_template("{spinner} {msg} [{elapsed}]")
                        .expect("valid template"),
                );
                bar.enable_steady_tick(Duration::from_millis(120));
                *self.current.borrow_mut() = Some(bar);
            }
        }
    }

    /// A detail line, shown with `-v` only.
    pub fn detail(&self, text: &str) {
        if self.mode == Mode::Lines {
            self.line(text);
        }
    }

    /// Clears the current spinner (before a summary or an error is printed).
    pub fn finish(&self) {
        if let Some(bar) = self.current.borrow_mut().take() {
            bar.finish_and_clear();
        }
    }

    fn line(&self, text: &str) {
        eprintln!(
            "vgsel-colmap: [{:7.2}s] {text}",
            self.started.elapsed().as_secs_f64()
        );
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.finish();
    }
}
