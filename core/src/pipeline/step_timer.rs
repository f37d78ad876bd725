//! [`timed`]: a step's wall time, added to its entry of the report's
//! [`StepTimes`](super::StepTimes) — the one place the pipeline reads the clock.

use std::time::Instant;

/// Runs `f` and adds its wall time (seconds) to `slot`.
///
/// ```ignore
/// let path = timed(&mut object.times.planning, || planner.plan(&start, &goals, seed));
/// ```
pub(super) fn timed<T>(slot: &mut f64, f: impl FnOnce() -> T) -> T {
    let start = Instant::now();
    let out = f();
    *slot += start.elapsed().as_secs_f64();
    out
}
