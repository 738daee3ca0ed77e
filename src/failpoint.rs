//! Kill points, for the tests that kill sapnet at each place it writes: with
//! `SAPNET_KILL_AT=<point>` in its environment, the process dies at that point as `kill -9`
//! would have it (an abort: no destructor, no flush, no cleanup). Unset, a point costs a
//! look at the environment, a few times per run.

/// The environment variable that names the point to die at.
pub const VARIABLE: &str = "SAPNET_KILL_AT";

/// Dies here if `SAPNET_KILL_AT` names `point`.
pub fn point(point: &str) {
    if std::env::var_os(VARIABLE).is_some_and(|v| v == point) {
        std::process::abort();
    }
}
