//! The `pinhole` binary (`pinhole --help`): runs the command line, and opens
//! the viewer when the command line asks for it.

use pinhole::cli::Outcome;

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
    let result = pinhole::cli::run().and_then(|outcome| match outcome {
        Outcome::Done => Ok(()),
        Outcome::OpenViewer { scene, screenshot } => pinhole::app::run(scene, screenshot),
    });
    pinhole::render::opengl::shutdown();
    if let Err(e) = result {
        eprintln!("pinhole: {e}");
        std::process::exit(1);
    }
}
