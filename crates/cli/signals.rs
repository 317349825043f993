//! SIGINT (Ctrl-C) and SIGTERM: the unfinished output folders of the run are removed, the user is
//! told what was discarded, and the process exits with 128 + the signal number (130, 143), as a
//! shell reports a process killed by it. An output closed early (`| head`, `| true`): the
//! unfinished folders are removed and the process ends by SIGPIPE, silently, as `cat` and `grep`
//! do ([`end_quietly_on_closed_output`], [`closed_output`]). Outputs already committed stay; an output folder is
//! never left half-written, because staged files reach it only by the all-or-nothing commit of
//! `contactscope_jobs::staging`, which a signal waits for.

use std::sync::atomic::{AtomicBool, Ordering};

/// Set when a signal arrived: the run's own error (a write into the removed staging folder)
/// must not race the handler's message and exit code.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Whether SIGINT or SIGTERM arrived; the handler thread is then about to exit the process.
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

/// Start the thread that waits for SIGINT and SIGTERM (Unix; elsewhere the default handling).
pub fn discard_on_interrupt() {
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGINT, SIGTERM};
        let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM]) else {
            return;
        };
        std::thread::spawn(move || {
            if let Some(signal) = signals.forever().next() {
                INTERRUPTED.store(true, Ordering::SeqCst);
                let removed = contactscope_jobs::staging::discard_unfinished();
                // A batch's lock goes too (its folder and finished series stay).
                let released = contactscope_jobs::batch::release_locks();
                let name = if signal == SIGINT {
                    "SIGINT"
                } else {
                    "SIGTERM"
                };
                let what = if removed.is_empty() {
                    "nothing was being written".to_string()
                } else {
                    let names: Vec<String> =
                        removed.iter().map(|p| p.display().to_string()).collect();
                    format!("discarded the unfinished output {}", names.join(", "))
                };
                let what = match released.len() {
                    0 => what,
                    _ => format!("{what}; released the batch's lock (finished series are kept)"),
                };
                // Not eprintln!: with stderr gone (a closed pipe) it would panic this thread
                // and the process would never exit.
                use std::io::Write as _;
                let _ = writeln!(
                    std::io::stderr(),
                    "contactscope: interrupted by {name}; {what}"
                );
                std::process::exit(128 + signal);
            }
        });
    }
}

/// Whether `e` comes from writing to a closed pipe (stdout or stderr read by a process that has
/// ended): the run then ends as [`end_by_sigpipe`] says, without a message.
pub fn closed_output(e: &anyhow::Error) -> bool {
    e.chain().any(|cause| {
        cause
            .downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// `println!`/`eprintln!` panic when their stream is a closed pipe (Rust ignores SIGPIPE, so the
/// write fails with EPIPE instead of ending the process). This hook turns that panic into what
/// `cat` does: no message, the process ended by SIGPIPE. Any other panic keeps the default
/// report.
pub fn end_quietly_on_closed_output() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or_default();
        if message.starts_with("failed printing to std") && message.contains("Broken pipe") {
            end_by_sigpipe();
        }
        default(info);
    }));
}

/// Remove the unfinished output folders, then end by SIGPIPE's default action (the exit status a
/// shell reports is 141, as for `cat` in the same place).
pub fn end_by_sigpipe() -> ! {
    contactscope_jobs::staging::discard_unfinished();
    #[cfg(unix)]
    {
        let _ = signal_hook::low_level::emulate_default_handler(signal_hook::consts::SIGPIPE);
    }
    std::process::exit(141)
}
