//! SIGINT (Ctrl-C) and SIGTERM: the unfinished output folders of the run are removed, the user is
//! told what was discarded, and the process exits with 128 + the signal number (130, 143), as a
//! shell reports a process killed by it. Outputs already committed stay; an output folder is
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
