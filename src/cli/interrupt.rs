//! Ctrl-C on the command line. The first press raises one process-wide
//! cancel flag that every long command polls (a render between bands, a
//! benchmark between frames, a chart or gallery between measurements): the
//! run stops, writes nothing and exits with 130, the shell's code for an
//! interrupt. Outputs are only ever written whole (by rename), after the
//! work, so an interrupted run leaves every file as it was. A second press
//! ends the process at once.

use std::sync::atomic::{AtomicBool, Ordering};

static CANCEL: AtomicBool = AtomicBool::new(false);

/// Exit code of an interrupted run (128 + SIGINT).
pub const EXIT_INTERRUPTED: i32 = 130;

/// Installs the handler (once; later calls do nothing).
pub fn install() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = ctrlc::set_handler(|| {
            if CANCEL.swap(true, Ordering::SeqCst) {
                std::process::exit(EXIT_INTERRUPTED);
            }
            eprintln!("\npinhole: interrupted; stopping without writing anything (Ctrl-C again to quit at once)");
        });
    });
}

/// The cancel flag long work polls.
pub fn flag() -> &'static AtomicBool {
    &CANCEL
}

/// Whether Ctrl-C was pressed.
pub fn interrupted() -> bool {
    CANCEL.load(Ordering::SeqCst)
}
