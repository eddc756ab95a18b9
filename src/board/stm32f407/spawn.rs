//! Spawning the board's tasks: each once, at start-up.

use embassy_executor::{SpawnError, SpawnToken};

/// A task's token: each task is spawned once, at start-up, so its pool always has room; a
/// second spawn is a bug, said plainly (no formatting of the executor's error).
pub fn spawned<S>(token: Result<SpawnToken<S>, SpawnError>) -> SpawnToken<S> {
    match token {
        Ok(token) => token,
        Err(_) => panic!("a task spawned twice"),
    }
}
