//! How a caller stops a long solve from outside: the model asks between its units of work
//! (a march step, a conjugate-gradient iteration, a root's evaluation) and gives up with
//! [`ModelError::Stopped`], so that a service's deadline or cancel takes effect inside one
//! continuum answer, not only between answers.

use std::fmt;

use crate::ModelError;

/// Asked between units of work whether to stop.
#[derive(Clone, Copy)]
pub struct Stop<'a>(Option<&'a (dyn Fn() -> bool + Sync)>);

impl<'a> Stop<'a> {
    /// A solve nobody stops (tests, tables built offline).
    pub const NEVER: Stop<'static> = Stop(None);

    /// Stops once `asked` says so.
    pub fn when(asked: &'a (dyn Fn() -> bool + Sync)) -> Stop<'a> {
        Stop(Some(asked))
    }

    /// `Err(ModelError::Stopped)` once the caller asks to stop.
    pub fn check(self) -> Result<(), ModelError> {
        match self.0 {
            Some(asked) if asked() => Err(ModelError::Stopped),
            _ => Ok(()),
        }
    }
}

impl fmt::Debug for Stop<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(if self.0.is_some() {
            "Stop(when asked)"
        } else {
            "Stop(never)"
        })
    }
}
