//! The process groups of the running engines, one registry for the whole
//! process, so that a process ending on a signal stops its engines first
//! ([`stop_running_engines`]): an engine left running would be reparented
//! to init and run on, busy or stuck, with whatever it started.
//!
//! Each engine is the leader of a process group of its own, whose id is
//! the leader's pid. An [`super::EngineSession`] registers the group when
//! it starts the engine (under the registry's lock, so the signal thread
//! never misses an engine being started) and removes it when it reaps the
//! leader (under the lock too, so the signal thread never signals a group
//! id that is no longer the engine's). Until the leader is reaped, its pid
//! (alive or a zombie) keeps the group's id reserved.

use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

/// How long [`stop_running_engines`] waits, after SIGTERM, for the engines
/// to exit before it kills what is left of their groups.
pub const STOP_GRACE: Duration = Duration::from_secs(1);

/// One running engine's process group.
pub(crate) struct Group {
    /// The group's id: the leader's pid.
    pub id: u32,
    /// Set once the leader has exited (not yet reaped).
    pub exited: Arc<AtomicBool>,
}

static GROUPS: Mutex<Vec<Group>> = Mutex::new(Vec::new());

/// The registry, locked. It stays consistent even if a holder panicked.
pub(crate) fn lock() -> MutexGuard<'static, Vec<Group>> {
    GROUPS
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Removes the group `id` from the locked registry `groups`.
pub(crate) fn remove(groups: &mut Vec<Group>, id: u32) {
    groups.retain(|g| g.id != id);
}

/// Stops every running engine, for a process about to exit on a signal:
/// SIGTERM to each engine's process group, up to `grace` for the engines
/// to exit, then SIGKILL to each group (what is left of it: an engine that
/// blocks or ignores SIGTERM, the processes it started). The registry stays
/// locked until the process exits, so no engine can be started, or reaped,
/// afterwards (a session that would, waits forever). Returns how many
/// engines were running.
pub fn stop_running_engines(grace: Duration) -> usize {
    let groups = lock();
    #[cfg(unix)]
    {
        signal_all(&groups, libc::SIGTERM);
        let deadline = std::time::Instant::now() + grace;
        while groups
            .iter()
            .any(|g| !g.exited.load(std::sync::atomic::Ordering::SeqCst))
            && std::time::Instant::now() < deadline
        {
            std::thread::sleep(Duration::from_millis(5));
        }
        // Also when every leader has exited: its zombie (reaped by no one
        // while the lock is held) keeps the group's id, so this reaches
        // only the processes it left in its group.
        signal_all(&groups, libc::SIGKILL);
    }
    #[cfg(not(unix))]
    let _ = grace;
    let count = groups.len();
    // Held until the process exits: see above.
    std::mem::forget(groups);
    count
}

/// Sends `signal` to every group of `groups`.
#[cfg(unix)]
fn signal_all(groups: &[Group], signal: libc::c_int) {
    for group in groups {
        if let Ok(id) = libc::pid_t::try_from(group.id) {
            // SAFETY: killpg only sends a signal; the id is a registered
            // engine's group, whose leader is not reaped yet.
            unsafe {
                libc::killpg(id, signal);
            }
        }
    }
}
