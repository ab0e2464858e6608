//! Status codes, enumerations passed as `int32_t`, version, and the thread-local error.

use std::ffi::{CStr, c_char, c_int};

use super::boundary::{self, write_message};
use crate::class::Class;
use crate::path::{EndReason, StartRoute};

/// Major version of the library this header belongs to (compare with `fricont_version()`
/// at run time to detect a header/library mismatch).
pub const FRICONT_VERSION_MAJOR: c_int = 0;
/// Minor version of the library this header belongs to.
pub const FRICONT_VERSION_MINOR: c_int = 1;
/// Patch version of the library this header belongs to.
pub const FRICONT_VERSION_PATCH: c_int = 0;

/// The result of every status-returning function.
///
/// * `0` (`FRICONT_OK`): success.
/// * positive: success with an *outcome* (what a step found): `FRICONT_TRANSITION`,
///   `FRICONT_FOLD`, `FRICONT_BIFURCATION`, `FRICONT_END`.
/// * negative: an error, in bands by kind: `-1xx` usage (a mistake in the call: NULL
///   pointer, length, range, order), `-2xx` data (the matrices cannot be used), `-3xx`
///   numerics and resources (memory), `-4xx` the caller's callbacks, `-5xx` internal (a
///   caught panic).
///
/// Every failing call stores a specific one-line message: on the handle it was given
/// (`fricont_problem_error_message`, `fricont_path_error_message`) and, always, in the
/// calling thread's last-error slot (`fricont_last_error_message`). Functions that take a
/// status as input take an `int32_t`.
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum fricont_status {
    /// Success.
    FRICONT_OK = 0,
    /// Outcome of a step: the path passed a transition point (one or more nodes changed
    /// class); the new events are at the end of the event list.
    FRICONT_TRANSITION = 1,
    /// Outcome of a step: a transition point at which α turns back (a non-smooth fold:
    /// past it, the solution for a given α is no longer unique).
    FRICONT_FOLD = 2,
    /// Outcome of a step: a transition point at which more than one neighbouring piece
    /// continues the path (a non-smooth bifurcation); the path took the unique
    /// orientation-preserving branch. The candidates are listed by
    /// `fricont_path_branch_count` / `fricont_path_branch` until the next step.
    /// Reported instead of `FRICONT_FOLD` when both hold (the event says both).
    FRICONT_BIFURCATION = 3,
    /// Outcome of a step: the path ended; `fricont_path_end_reason` says why.
    FRICONT_END = 4,
    /// Usage: a required pointer argument (handle, input array with positive length,
    /// output pointer) is NULL.
    FRICONT_ERR_NULL = -101,
    /// Usage: an array length or a dimension does not fit (a load of the wrong length, a
    /// friction or gap array that is not p long, N with another number of columns than
    /// A, an output buffer that is too short, a negative length).
    FRICONT_ERR_LENGTH = -102,
    /// Usage: a parameter is out of its documented range (F < 0, r ≤ 0, an empty α window,
    /// an unknown storage code, an event index past the end, α outside the window, …).
    FRICONT_ERR_RANGE = -103,
    /// Usage: a call made in the wrong order (querying or stepping a path that was not
    /// started, setting path options after the start, choosing a branch where there is no
    /// bifurcation, starting without an α window), or a call into a path from inside one
    /// of its own load callbacks (which would re-enter a step under way).
    FRICONT_ERR_ORDER = -104,
    /// Usage: the displacement u was asked of a problem that cannot compute it (made by
    /// `fricont_problem_new_condensed`): pass NULL for u there.
    FRICONT_ERR_UNAVAILABLE = -105,
    /// Data: a malformed CSR matrix (index base not 0 or 1, row pointer not starting at
    /// the base or decreasing or not ending at the base + nnz, a column index out of
    /// range or negative, an entry of A in the wrong triangle for the storage; duplicate
    /// entries are not an error: they are summed).
    FRICONT_ERR_CSR = -201,
    /// Data: a NaN or infinite value in A, N, T (also duplicates whose sum overflows), the
    /// gap, a guess or a load vector.
    FRICONT_ERR_NONFINITE = -202,
    /// Data: A given in full storage, or a condensed W, is not symmetric (relative
    /// tolerance 1e-10), or the W formed with a host's solve is not (1e-8).
    FRICONT_ERR_NOT_SYMMETRIC = -203,
    /// Data: A, or a condensed W, is not positive definite (the message names the failing
    /// pivot's row).
    FRICONT_ERR_NOT_SPD = -204,
    /// Data: B = [N; T] does not have full row rank 2p (the message names the row).
    FRICONT_ERR_RANK_DEFICIENT = -205,
    /// Numerics: the fixed-α solve that starts a path did not converge.
    FRICONT_ERR_SOLVE_FAILED = -301,
    /// Numerics: a numerical failure while tracing (the message says which).
    FRICONT_ERR_NUMERICAL = -302,
    /// Resources: an allocation failed (the message says what and how many bytes). The
    /// call changed nothing; the handles stay usable (free something, or use a smaller
    /// problem, and call again).
    FRICONT_ERR_OUT_OF_MEMORY = -303,
    /// Callback: a load callback returned a nonzero code; the step was aborted and the
    /// path ended (reason `FRICONT_END_FAILED`), keeping what it had traced. The code is
    /// returned by `fricont_path_callback_code`.
    FRICONT_ERR_CALLBACK = -401,
    /// Callback: a load callback returned 0 but wrote a NaN or infinite value; handled as
    /// `FRICONT_ERR_CALLBACK` (callback code 0).
    FRICONT_ERR_CALLBACK_VALUE = -402,
    /// Callback: the host's solve (`fricont_problem_new_solve`) failed: it returned a
    /// negative code, a positive (recoverable) code twice in a row for the same block (it
    /// is retried once), or wrote a NaN or infinite value. Its code is in the message
    /// and, for a path, in `fricont_path_callback_code` (0 for NaN/Inf).
    FRICONT_ERR_SOLVE_CALLBACK = -403,
    /// Internal: a panic (a bug in fricont) was caught at the C boundary. The message says
    /// where; the handle is poisoned (every later call on it returns
    /// `FRICONT_ERR_POISONED`) and should be freed.
    FRICONT_ERR_PANIC = -501,
    /// Internal: the handle was poisoned by an earlier `FRICONT_ERR_PANIC`.
    FRICONT_ERR_POISONED = -502,
}

impl fricont_status {
    /// Every status, for tests and `fricont_status_str`.
    pub const ALL: [fricont_status; 23] = {
        use fricont_status::*;
        [
            FRICONT_OK,
            FRICONT_TRANSITION,
            FRICONT_FOLD,
            FRICONT_BIFURCATION,
            FRICONT_END,
            FRICONT_ERR_NULL,
            FRICONT_ERR_LENGTH,
            FRICONT_ERR_RANGE,
            FRICONT_ERR_ORDER,
            FRICONT_ERR_UNAVAILABLE,
            FRICONT_ERR_CSR,
            FRICONT_ERR_NONFINITE,
            FRICONT_ERR_NOT_SYMMETRIC,
            FRICONT_ERR_NOT_SPD,
            FRICONT_ERR_RANK_DEFICIENT,
            FRICONT_ERR_SOLVE_FAILED,
            FRICONT_ERR_NUMERICAL,
            FRICONT_ERR_OUT_OF_MEMORY,
            FRICONT_ERR_CALLBACK,
            FRICONT_ERR_CALLBACK_VALUE,
            FRICONT_ERR_SOLVE_CALLBACK,
            FRICONT_ERR_PANIC,
            FRICONT_ERR_POISONED,
        ]
    };

    /// The enumerator's name and a short description, NUL-terminated.
    fn text(self) -> &'static str {
        use fricont_status::*;
        match self {
            FRICONT_OK => "FRICONT_OK: success\0",
            FRICONT_TRANSITION => "FRICONT_TRANSITION: the path passed a transition point\0",
            FRICONT_FOLD => "FRICONT_FOLD: a transition point where alpha turns back (fold)\0",
            FRICONT_BIFURCATION => {
                "FRICONT_BIFURCATION: a transition point with several continuing pieces\0"
            }
            FRICONT_END => "FRICONT_END: the path ended (see fricont_path_end_reason)\0",
            FRICONT_ERR_NULL => "FRICONT_ERR_NULL: a required pointer argument is NULL\0",
            FRICONT_ERR_LENGTH => "FRICONT_ERR_LENGTH: an array length or dimension does not fit\0",
            FRICONT_ERR_RANGE => "FRICONT_ERR_RANGE: a parameter is out of its range\0",
            FRICONT_ERR_ORDER => {
                "FRICONT_ERR_ORDER: a call made in the wrong order, or into a path from its own load callback\0"
            }
            FRICONT_ERR_UNAVAILABLE => {
                "FRICONT_ERR_UNAVAILABLE: u is not available for a problem made from condensed data\0"
            }
            FRICONT_ERR_CSR => "FRICONT_ERR_CSR: a malformed CSR matrix\0",
            FRICONT_ERR_NONFINITE => "FRICONT_ERR_NONFINITE: a NaN or infinite input value\0",
            FRICONT_ERR_NOT_SYMMETRIC => "FRICONT_ERR_NOT_SYMMETRIC: A or W is not symmetric\0",
            FRICONT_ERR_NOT_SPD => "FRICONT_ERR_NOT_SPD: A or W is not positive definite\0",
            FRICONT_ERR_RANK_DEFICIENT => {
                "FRICONT_ERR_RANK_DEFICIENT: B = [N; T] does not have full row rank\0"
            }
            FRICONT_ERR_SOLVE_FAILED => "FRICONT_ERR_SOLVE_FAILED: the fixed-alpha solve failed\0",
            FRICONT_ERR_NUMERICAL => "FRICONT_ERR_NUMERICAL: a numerical failure while tracing\0",
            FRICONT_ERR_OUT_OF_MEMORY => "FRICONT_ERR_OUT_OF_MEMORY: an allocation failed\0",
            FRICONT_ERR_CALLBACK => {
                "FRICONT_ERR_CALLBACK: a load callback returned a nonzero code\0"
            }
            FRICONT_ERR_CALLBACK_VALUE => {
                "FRICONT_ERR_CALLBACK_VALUE: a load callback wrote a NaN or infinite value\0"
            }
            FRICONT_ERR_SOLVE_CALLBACK => {
                "FRICONT_ERR_SOLVE_CALLBACK: the host's solve callback failed\0"
            }
            FRICONT_ERR_PANIC => {
                "FRICONT_ERR_PANIC: internal error (panic caught at the C boundary)\0"
            }
            FRICONT_ERR_POISONED => {
                "FRICONT_ERR_POISONED: the handle was poisoned by an earlier internal error\0"
            }
        }
    }
}

/// Class of a contact node, as written into `int32_t` class arrays and
/// `fricont_event.from` / `.to`. With d = B u − (g, 0) = (dν, dt) (the normal gap change
/// and the tangential displacement at the nodes), each class has two equations and
/// guards that hold strictly inside a smooth piece:
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum fricont_class {
    /// No contact: λν = λt = 0, guard dν < 0.
    FRICONT_OPEN = 0,
    /// Contact, stick: dν = dt = 0, guards λν < 0, F λν < λt < −F λν (never at a
    /// frictionless node, F = 0: its region is empty there).
    FRICONT_STICK = 1,
    /// Contact, slip in +t: dν = 0, λt = F λν, guards λν < 0, dt > 0. A frictionless
    /// node in contact is in slip+ or slip- by the sign of its dt; where dt stays at zero
    /// it keeps the sign it had (slip+ where it touched down so).
    FRICONT_SLIP_PLUS = 2,
    /// Contact, slip in −t: dν = 0, λt = −F λν, guards λν < 0, dt < 0.
    FRICONT_SLIP_MINUS = 3,
}

/// The class code of a Rust class.
pub(crate) fn class_code(c: Class) -> i32 {
    match c {
        Class::Open => fricont_class::FRICONT_OPEN as i32,
        Class::Stick => fricont_class::FRICONT_STICK as i32,
        Class::SlipPlus => fricont_class::FRICONT_SLIP_PLUS as i32,
        Class::SlipMinus => fricont_class::FRICONT_SLIP_MINUS as i32,
    }
}

/// Which part of the symmetric stiffness matrix A the caller passes (an `int32_t`
/// argument of `fricont_problem_new`).
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum fricont_storage {
    /// Both triangles; symmetry is checked (relative tolerance 1e-10 of max |A_ij|).
    FRICONT_STORAGE_FULL = 0,
    /// Only the entries with row ≥ column; an entry above the diagonal is an error.
    FRICONT_STORAGE_LOWER = 1,
    /// Only the entries with row ≤ column; an entry below the diagonal is an error.
    FRICONT_STORAGE_UPPER = 2,
}

/// Why a path ended (`fricont_path_end_reason`).
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum fricont_end_reason {
    /// The path has not ended.
    FRICONT_END_NONE = 0,
    /// α reached the edge of the window.
    FRICONT_END_WINDOW = 1,
    /// The step limit (`fricont_path_set_max_steps`) was reached.
    FRICONT_END_MAX_STEPS = 2,
    /// The path came back to a point and piece it had already traced (a closed loop).
    FRICONT_END_CLOSED_LOOP = 3,
    /// A bifurcation without a unique orientation-preserving branch: choose one with
    /// `fricont_path_choose_branch` and step on.
    FRICONT_END_BIFURCATION = 4,
    /// A failure (a load callback, numerics); the path keeps what it traced. The error
    /// message of the failing call says what happened.
    FRICONT_END_FAILED = 5,
    /// The monitor (`fricont_path_set_monitor`) asked to stop. Not final:
    /// `fricont_path_step` and `fricont_path_run` continue from where the path stopped.
    FRICONT_END_STOPPED = 6,
}

impl fricont_end_reason {
    /// Every end reason, in code order.
    pub const ALL: [fricont_end_reason; 7] = {
        use fricont_end_reason::*;
        [
            FRICONT_END_NONE,
            FRICONT_END_WINDOW,
            FRICONT_END_MAX_STEPS,
            FRICONT_END_CLOSED_LOOP,
            FRICONT_END_BIFURCATION,
            FRICONT_END_FAILED,
            FRICONT_END_STOPPED,
        ]
    };

    /// The code of a path's end reason (`None`: not ended).
    pub(crate) fn of(reason: Option<&EndReason>) -> Self {
        use fricont_end_reason::*;
        match reason {
            None => FRICONT_END_NONE,
            Some(EndReason::Window) => FRICONT_END_WINDOW,
            Some(EndReason::MaxSteps) => FRICONT_END_MAX_STEPS,
            Some(EndReason::ClosedLoop) => FRICONT_END_CLOSED_LOOP,
            Some(EndReason::Bifurcation) => FRICONT_END_BIFURCATION,
            Some(EndReason::Failed(_)) => FRICONT_END_FAILED,
            Some(EndReason::Stopped) => FRICONT_END_STOPPED,
        }
    }

    /// [`EndReason::name`] as a C string (`"none"` for `FRICONT_END_NONE`).
    fn name(self) -> &'static CStr {
        use fricont_end_reason::*;
        match self {
            FRICONT_END_NONE => c"none",
            FRICONT_END_WINDOW => c"window",
            FRICONT_END_MAX_STEPS => c"max_steps",
            FRICONT_END_CLOSED_LOOP => c"closed_loop",
            FRICONT_END_BIFURCATION => c"bifurcation",
            FRICONT_END_FAILED => c"failed",
            FRICONT_END_STOPPED => c"stopped",
        }
    }
}

/// How `fricont_path_start` reached the start point (`fricont_path_start_route`). Every
/// route ends in the same check: the start point solves the problem at the start's α to
/// 1e-12 relative. Where the problem has several solutions there (large friction, a path
/// that folds back over α), the route says which search picked this one.
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum fricont_start_route {
    /// The fixed-α solver at α, from the guess or from zero forces.
    FRICONT_START_SOLVED = 0,
    /// The solver failed at α, and so did the paths of `FRICONT_START_ZERO_LOAD` and
    /// `FRICONT_START_OPEN`; a path traced from a nearby α reached it.
    FRICONT_START_NEARBY = 1,
    /// The solver failed at α; the path of the load `tau f(alpha)` from zero load
    /// (tau = 0) reached it at tau = 1.
    FRICONT_START_ZERO_LOAD = 2,
    /// As `FRICONT_START_ZERO_LOAD`, but that path could not leave tau = 0 (every gap
    /// zero); the path from a load that holds every node open reached it.
    FRICONT_START_OPEN = 3,
}

impl fricont_start_route {
    /// Every start route, in code order.
    pub const ALL: [fricont_start_route; 4] = {
        use fricont_start_route::*;
        [
            FRICONT_START_SOLVED,
            FRICONT_START_NEARBY,
            FRICONT_START_ZERO_LOAD,
            FRICONT_START_OPEN,
        ]
    };

    /// The code of a start route.
    pub(crate) fn of(route: StartRoute) -> Self {
        use fricont_start_route::*;
        match route {
            StartRoute::Solved => FRICONT_START_SOLVED,
            StartRoute::Nearby => FRICONT_START_NEARBY,
            StartRoute::ZeroLoad => FRICONT_START_ZERO_LOAD,
            StartRoute::Open => FRICONT_START_OPEN,
        }
    }

    /// [`StartRoute::name`] as a C string.
    fn name(self) -> &'static CStr {
        use fricont_start_route::*;
        match self {
            FRICONT_START_SOLVED => c"solved",
            FRICONT_START_NEARBY => c"nearby",
            FRICONT_START_ZERO_LOAD => c"zero_load",
            FRICONT_START_OPEN => c"open",
        }
    }
}

/// A static, NUL-terminated description of a status code: the enumerator's name, a colon
/// and one line (e.g. `"FRICONT_ERR_NULL: a required pointer argument is NULL"`).
///
/// `status` is any `int32_t`; an unknown code gives `"unknown fricont status code"`.
/// The returned string is owned by the library, valid forever; never free it.
/// Thread-safe.
#[unsafe(no_mangle)]
pub extern "C" fn fricont_status_str(status: i32) -> *const c_char {
    boundary::run_value(c"unknown fricont status code".as_ptr(), || {
        fricont_status::ALL
            .iter()
            .find(|s| **s as i32 == status)
            .map(|s| s.text().as_ptr().cast::<c_char>())
            .unwrap_or(c"unknown fricont status code".as_ptr())
    })
}

/// The name of a class code (`fricont_class`): `"open"`, `"stick"`, `"slip+"`, `"slip-"`
/// (the names of the JSON exchange format), or `"unknown"` for any other value.
///
/// The returned string is static (never free it). Thread-safe.
#[unsafe(no_mangle)]
pub extern "C" fn fricont_class_name(class_code: i32) -> *const c_char {
    boundary::run_value(c"unknown".as_ptr(), || match class_code {
        0 => c"open".as_ptr(),
        1 => c"stick".as_ptr(),
        2 => c"slip+".as_ptr(),
        3 => c"slip-".as_ptr(),
        _ => c"unknown".as_ptr(),
    })
}

/// The name of an end reason code (`fricont_end_reason`, from `fricont_path_end_reason`):
/// `"none"`, `"window"`, `"max_steps"`, `"closed_loop"`, `"bifurcation"`, `"failed"`,
/// `"stopped"` (the names of the JSON exchange format and of the Python and MATLAB
/// bindings), or `"unknown"` for any other value.
///
/// The returned string is static (never free it). Thread-safe.
#[unsafe(no_mangle)]
pub extern "C" fn fricont_end_reason_name(reason: i32) -> *const c_char {
    boundary::run_value(c"unknown".as_ptr(), || {
        fricont_end_reason::ALL
            .iter()
            .find(|r| **r as i32 == reason)
            .map_or(c"unknown", |r| r.name())
            .as_ptr()
    })
}

/// The name of a start route code (`fricont_start_route`, from
/// `fricont_path_start_route`): `"solved"`, `"nearby"`, `"zero_load"`, `"open"` (the names
/// of the Python and MATLAB bindings), or `"unknown"` for any other value.
///
/// The returned string is static (never free it). Thread-safe.
#[unsafe(no_mangle)]
pub extern "C" fn fricont_start_route_name(route: i32) -> *const c_char {
    boundary::run_value(c"unknown".as_ptr(), || {
        fricont_start_route::ALL
            .iter()
            .find(|r| **r as i32 == route)
            .map_or(c"unknown", |r| r.name())
            .as_ptr()
    })
}

/// The library's version, `"MAJOR.MINOR.PATCH"` (static, NUL-terminated; never free it).
/// Compare with `FRICONT_VERSION_MAJOR` etc. to detect a header that does not match the
/// library you linked. Thread-safe.
#[unsafe(no_mangle)]
pub extern "C" fn fricont_version() -> *const c_char {
    boundary::run_value(std::ptr::null(), || {
        concat!(env!("CARGO_PKG_VERSION"), "\0")
            .as_ptr()
            .cast::<c_char>()
    })
}

/// Copies the calling thread's last error message (set by every failing call on this
/// thread, including constructors that have no handle yet and calls given a NULL handle)
/// into `buf`, with `snprintf` semantics.
///
/// * `buf`: caller-owned, may be NULL (then nothing is written).
/// * `len`: size of `buf` in bytes; at most `len - 1` bytes and a terminating NUL are
///   written (the text is cut at a UTF-8 character boundary; messages are UTF-8).
///
/// Returns the full length of the message in bytes, not counting the NUL (0 when no call
/// on this thread has failed yet): a return value `≥ len` means the text was cut.
/// A successful call does not clear the message.
///
/// # Safety
/// `buf` is NULL or valid for `len` bytes of writes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fricont_last_error_message(buf: *mut c_char, len: usize) -> usize {
    boundary::run_value(0, || {
        let msg = boundary::last_error();
        // SAFETY: by this function's contract.
        unsafe { write_message(&msg, buf, len) }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn version_macros_match_cargo_toml() {
        let parse = |s: &str| s.parse::<c_int>().unwrap();
        assert_eq!(
            FRICONT_VERSION_MAJOR,
            parse(env!("CARGO_PKG_VERSION_MAJOR"))
        );
        assert_eq!(
            FRICONT_VERSION_MINOR,
            parse(env!("CARGO_PKG_VERSION_MINOR"))
        );
        assert_eq!(
            FRICONT_VERSION_PATCH,
            parse(env!("CARGO_PKG_VERSION_PATCH"))
        );
        let v = unsafe { std::ffi::CStr::from_ptr(fricont_version()) };
        assert_eq!(
            v.to_str().unwrap(),
            format!("{FRICONT_VERSION_MAJOR}.{FRICONT_VERSION_MINOR}.{FRICONT_VERSION_PATCH}")
        );
    }

    #[test]
    fn every_status_has_its_own_text() {
        for s in fricont_status::ALL {
            let t = unsafe { std::ffi::CStr::from_ptr(fricont_status_str(s as i32)) };
            let t = t.to_str().unwrap();
            assert!(t.starts_with(&format!("{s:?}:")), "{t}");
        }
        let t = unsafe { std::ffi::CStr::from_ptr(fricont_status_str(12345)) };
        assert_eq!(t.to_str().unwrap(), "unknown fricont status code");
    }

    fn c_str(p: *const c_char) -> &'static str {
        unsafe { CStr::from_ptr(p) }.to_str().unwrap()
    }

    #[test]
    fn end_reason_and_start_route_names_are_the_rust_names() {
        let reasons = [
            EndReason::Window,
            EndReason::MaxSteps,
            EndReason::ClosedLoop,
            EndReason::Bifurcation,
            EndReason::Failed("x".into()),
            EndReason::Stopped,
        ];
        assert_eq!(c_str(fricont_end_reason_name(0)), "none");
        for r in &reasons {
            let code = fricont_end_reason::of(Some(r)) as i32;
            assert_eq!(c_str(fricont_end_reason_name(code)), r.name());
        }
        let routes = [
            StartRoute::Solved,
            StartRoute::Nearby,
            StartRoute::ZeroLoad,
            StartRoute::Open,
        ];
        for r in routes {
            let code = fricont_start_route::of(r) as i32;
            assert_eq!(c_str(fricont_start_route_name(code)), r.name());
        }
        // Every code is one of those, in order; any other value is "unknown".
        assert_eq!(fricont_end_reason::ALL.len(), reasons.len() + 1);
        assert_eq!(fricont_start_route::ALL.len(), routes.len());
        for (k, r) in fricont_end_reason::ALL.iter().enumerate() {
            assert_eq!(*r as i32, k as i32);
        }
        for (k, r) in fricont_start_route::ALL.iter().enumerate() {
            assert_eq!(*r as i32, k as i32);
        }
        for bad in [-1, 7, i32::MIN, i32::MAX] {
            assert_eq!(c_str(fricont_end_reason_name(bad)), "unknown");
        }
        for bad in [-1, 4, i32::MIN, i32::MAX] {
            assert_eq!(c_str(fricont_start_route_name(bad)), "unknown");
        }
    }

    #[test]
    fn class_codes_follow_the_rust_discriminants() {
        for c in Class::ALL {
            assert_eq!(class_code(c), c as u8 as i32);
            let name = unsafe { std::ffi::CStr::from_ptr(fricont_class_name(class_code(c))) };
            assert_eq!(name.to_str().unwrap(), c.name());
        }
    }
}
