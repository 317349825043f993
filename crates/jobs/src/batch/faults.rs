//! A hook for the batch's fault-injection tests: with `CONTACTSCOPE_TEST_PAUSE=STEP=MS[,STEP=MS…]`
//! in the environment, the batch sleeps MS milliseconds at each named step, so that a test can
//! kill it, or start a second batch, at exactly that point. Without the variable (every real
//! run) a step costs one environment lookup.
//!
//! Steps: `folder-checked` (the batch's folder was looked at, nothing made yet),
//! `folder-made` (made or found, not yet locked), `folder-locked` (locked, not yet set up),
//! `record-removed` (a series' old record is gone, its folders not yet replaced),
//! `series-committed` (its `series/ID/` is in place, its fit and record not yet written),
//! `fit-committed` (its `fit/ID/` is in place, its record not yet written).

/// The variable a test sets.
pub const VARIABLE: &str = "CONTACTSCOPE_TEST_PAUSE";

/// Sleep as the environment asks at `step` (module docs).
pub(crate) fn pause(step: &str) {
    let Ok(spec) = std::env::var(VARIABLE) else {
        return;
    };
    let millis = spec
        .split(',')
        .filter_map(|item| item.split_once('='))
        .find(|(name, _)| name.trim() == step)
        .and_then(|(_, ms)| ms.trim().parse::<u64>().ok());
    if let Some(ms) = millis {
        std::thread::sleep(std::time::Duration::from_millis(ms.min(600_000)));
    }
}
