//! The `pinhole` binary: see CLI.md, or `pinhole --help`.

fn main() {
    // A bug must still end in one sentence, not a backtrace.
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_default();
        let at = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
        eprintln!("pinhole: internal error{at}: {msg} (please report this)");
    }));
    if let Err(e) = pinhole::cli::run() {
        eprintln!("pinhole: {e}");
        std::process::exit(1);
    }
}
