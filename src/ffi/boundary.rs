//! The panic boundary, error messages and pointer/slice checks shared by every export.
//!
//! Every exported function runs its body through [`run`] (status-returning functions) or
//! [`run_value`] (the few that return a value), usually via the [`ffi_boundary!`] macro:
//!
//! * a handle that an earlier panic poisoned is refused with `FRICONT_ERR_POISONED`;
//! * the body returns `Result<fricont_status, Failure>`; a failure's message is stored on
//!   the handle (if the call has one) and in the calling thread's last-error slot;
//! * a panic is caught (`catch_unwind`), its message and location stored the same way,
//!   the handle poisoned, and `FRICONT_ERR_PANIC` returned. A process-wide panic hook,
//!   installed once and chained to the previous hook, keeps panics inside the boundary
//!   from printing (the library never prints); panics elsewhere reach the previous hook.

use std::cell::{Cell, RefCell};
use std::ffi::c_char;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::sync::{Mutex, Once};

use super::status::fricont_status;
use crate::error::Error;

/// Per-handle error state: the message of the most recent failing call, the poison flag
/// set by a caught panic, and the code of the most recent failing load callback.
#[derive(Debug, Default)]
pub(crate) struct ErrorSlot {
    message: Mutex<String>,
    poisoned: AtomicBool,
    callback_code: AtomicI32,
}

impl ErrorSlot {
    pub(crate) fn set_message(&self, msg: &str) {
        let mut m = self.message.lock().unwrap_or_else(|e| e.into_inner());
        m.clear();
        m.push_str(msg);
    }

    pub(crate) fn message(&self) -> String {
        self.message
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }

    pub(crate) fn is_poisoned(&self) -> bool {
        self.poisoned.load(Ordering::SeqCst)
    }

    pub(crate) fn poison(&self) {
        self.poisoned.store(true, Ordering::SeqCst);
    }

    pub(crate) fn set_callback_code(&self, code: i32) {
        self.callback_code.store(code, Ordering::SeqCst);
    }

    pub(crate) fn callback_code(&self) -> i32 {
        self.callback_code.load(Ordering::SeqCst)
    }
}

/// Anything with an [`ErrorSlot`] (the two handle types).
pub(crate) trait HasSlot {
    fn slot(&self) -> &ErrorSlot;
}

/// A failed call: the status to return and a specific message.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Failure {
    pub(crate) status: fricont_status,
    pub(crate) message: String,
    /// The load callback's own code, for `FRICONT_ERR_CALLBACK*`.
    pub(crate) callback_code: Option<i32>,
}

impl Failure {
    pub(crate) fn new(status: fricont_status, message: impl Into<String>) -> Self {
        Self {
            status,
            message: message.into(),
            callback_code: None,
        }
    }
    pub(crate) fn null(what: &str) -> Self {
        Self::new(fricont_status::FRICONT_ERR_NULL, format!("{what} is NULL"))
    }
    pub(crate) fn length(message: impl Into<String>) -> Self {
        Self::new(fricont_status::FRICONT_ERR_LENGTH, message)
    }
    pub(crate) fn range(message: impl Into<String>) -> Self {
        Self::new(fricont_status::FRICONT_ERR_RANGE, message)
    }
    pub(crate) fn order(message: impl Into<String>) -> Self {
        Self::new(fricont_status::FRICONT_ERR_ORDER, message)
    }
}

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        use fricont_status::*;
        let message = e.to_string();
        let (status, callback_code) = match &e {
            Error::Dimension(_) => (FRICONT_ERR_LENGTH, None),
            Error::Csr(_) => (FRICONT_ERR_CSR, None),
            Error::NonFinite(_) => (FRICONT_ERR_NONFINITE, None),
            Error::NotSymmetric(_) => (FRICONT_ERR_NOT_SYMMETRIC, None),
            Error::NotSpd { .. } | Error::WNotSpd(_) => (FRICONT_ERR_NOT_SPD, None),
            Error::HostSolve { code, .. } => (FRICONT_ERR_SOLVE_CALLBACK, Some(*code)),
            Error::NoDisplacement(_) => (FRICONT_ERR_UNAVAILABLE, None),
            Error::RankDeficient(_) => (FRICONT_ERR_RANK_DEFICIENT, None),
            Error::InvalidParameter(_) => (FRICONT_ERR_RANGE, None),
            Error::Load { code: 0, .. } => (FRICONT_ERR_CALLBACK_VALUE, Some(0)),
            Error::Load { code, .. } => (FRICONT_ERR_CALLBACK, Some(*code)),
            Error::SolveFailed { .. } => (FRICONT_ERR_SOLVE_FAILED, None),
            Error::Numerical(_) => (FRICONT_ERR_NUMERICAL, None),
            Error::OutOfMemory(_) => (FRICONT_ERR_OUT_OF_MEMORY, None),
            Error::Usage(_) => (FRICONT_ERR_ORDER, None),
        };
        Self {
            status,
            message,
            callback_code,
        }
    }
}

/// Result of a body inside the boundary.
pub(crate) type FfiResult<T = fricont_status> = Result<T, Failure>;

thread_local! {
    static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
    static IN_BOUNDARY: Cell<u32> = const { Cell::new(0) };
    static PANIC_MESSAGE: RefCell<Option<String>> = const { RefCell::new(None) };
}

static HOOK: Once = Once::new();

/// Installs (once per process) a panic hook that records panics raised inside the
/// boundary instead of printing them, and defers to the previous hook otherwise.
fn install_hook() {
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if IN_BOUNDARY.with(|c| c.get()) > 0 {
                let payload = payload_text(info.payload());
                let text = match info.location() {
                    Some(l) => format!("{payload} (at {}:{}:{})", l.file(), l.line(), l.column()),
                    None => payload,
                };
                PANIC_MESSAGE.with(|m| *m.borrow_mut() = Some(text));
            } else {
                previous(info);
            }
        }));
    });
}

fn payload_text(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "a panic with a non-text payload".to_string()
    }
}

/// Stores `msg` as the thread's last error and, if given, on the handle.
pub(crate) fn record(slot: Option<&ErrorSlot>, msg: &str) {
    LAST_ERROR.with(|e| {
        let mut e = e.borrow_mut();
        e.clear();
        e.push_str(msg);
    });
    if let Some(s) = slot {
        s.set_message(msg);
    }
}

/// The calling thread's last error message.
pub(crate) fn last_error() -> String {
    LAST_ERROR.with(|e| e.borrow().clone())
}

/// Runs `f` under `catch_unwind` with the hook silenced; `Err(message)` on a panic.
fn catch<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    install_hook();
    IN_BOUNDARY.with(|c| c.set(c.get() + 1));
    let r = catch_unwind(AssertUnwindSafe(f));
    IN_BOUNDARY.with(|c| c.set(c.get() - 1));
    r.map_err(|payload| {
        PANIC_MESSAGE
            .with(|m| m.borrow_mut().take())
            .unwrap_or_else(|| payload_text(payload.as_ref()))
    })
}

/// The boundary for status-returning exports (see the module documentation).
pub(crate) fn run(slot: Option<&ErrorSlot>, f: impl FnOnce() -> FfiResult) -> fricont_status {
    if let Some(s) = slot
        && s.is_poisoned()
    {
        record(
            slot,
            "the handle is poisoned: an earlier call on it panicked (see the message of that call); free it",
        );
        return fricont_status::FRICONT_ERR_POISONED;
    }
    match catch(f) {
        Ok(Ok(status)) => status,
        Ok(Err(failure)) => {
            if let (Some(s), Some(code)) = (slot, failure.callback_code) {
                s.set_callback_code(code);
            }
            record(slot, &failure.message);
            failure.status
        }
        Err(panic) => {
            if let Some(s) = slot {
                s.poison();
            }
            record(
                slot,
                &format!("internal error (panic caught at the C boundary): {panic}"),
            );
            fricont_status::FRICONT_ERR_PANIC
        }
    }
}

/// The boundary for exports that return a plain value: `fallback` on a panic.
pub(crate) fn run_value<T>(fallback: T, f: impl FnOnce() -> T) -> T {
    match catch(f) {
        Ok(v) => v,
        Err(panic) => {
            record(
                None,
                &format!("internal error (panic caught at the C boundary): {panic}"),
            );
            fallback
        }
    }
}

/// `run` with the error slot of the handle behind a raw pointer (NULL: no slot).
///
/// `ffi_boundary!(handle_ptr => body)` or `ffi_boundary!(body)` (no handle).
macro_rules! ffi_boundary {
    ($handle:expr => $body:expr) => {{
        // SAFETY: the caller passes NULL or a live handle from the matching `_new`.
        let slot = unsafe { $handle.as_ref() }.map($crate::ffi::boundary::HasSlot::slot);
        $crate::ffi::boundary::run(slot, || $body)
    }};
    ($body:expr) => {{ $crate::ffi::boundary::run(None, || $body) }};
}
pub(crate) use ffi_boundary;

/// Writes `msg` into `buf` with `snprintf` semantics: at most `len - 1` bytes and a NUL
/// (cut at a UTF-8 character boundary), nothing if `buf` is NULL or `len` is 0. Returns the
/// full length of the message in bytes, without the NUL.
///
/// # Safety
/// `buf` is NULL or valid for `len` bytes of writes.
pub(crate) unsafe fn write_message(msg: &str, buf: *mut c_char, len: usize) -> usize {
    if !buf.is_null() && len > 0 {
        let mut k = msg.len().min(len - 1);
        while !msg.is_char_boundary(k) {
            k -= 1;
        }
        // SAFETY: k < len bytes are written, then the NUL at k < len.
        unsafe {
            std::ptr::copy_nonoverlapping(msg.as_ptr(), buf.cast::<u8>(), k);
            *buf.add(k) = 0;
        }
    }
    msg.len()
}

/// A shared reference to a handle, or `FRICONT_ERR_NULL`.
///
/// # Safety
/// `ptr` is NULL or a live handle.
pub(crate) unsafe fn handle_ref<'a, T>(ptr: *const T, what: &str) -> FfiResult<&'a T> {
    // SAFETY: by the caller's contract.
    unsafe { ptr.as_ref() }.ok_or_else(|| Failure::null(what))
}

/// A checked `int64_t` length: `FRICONT_ERR_LENGTH` when negative.
pub(crate) fn len_of(len: i64, what: &str) -> FfiResult<usize> {
    usize::try_from(len)
        .ok()
        .filter(|&l| l <= isize::MAX as usize / 8)
        .ok_or_else(|| Failure::length(format!("{what} = {len} is not a valid length")))
}

/// An input array of `len` elements: `&[]` for length 0 (the pointer may then be NULL),
/// `FRICONT_ERR_NULL` for a NULL pointer with a positive length.
///
/// # Safety
/// `ptr` is NULL or valid for reading `len` elements during the call.
pub(crate) unsafe fn slice_in<'a, T>(ptr: *const T, len: usize, what: &str) -> FfiResult<&'a [T]> {
    if len == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(Failure::null(&format!("{what} (length {len})")));
    }
    // SAFETY: non-NULL and valid for `len` reads by the caller's contract.
    Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
}

/// An optional output buffer: `None` for NULL, else the first `need` elements, or
/// `FRICONT_ERR_LENGTH` when the caller's `len` is smaller than `need`.
///
/// # Safety
/// `ptr` is NULL or valid for writing `len` elements during the call.
pub(crate) unsafe fn slice_out<'a, T>(
    ptr: *mut T,
    len: i64,
    need: usize,
    what: &str,
) -> FfiResult<Option<&'a mut [T]>> {
    if ptr.is_null() {
        return Ok(None);
    }
    if len < 0 || (len as u64) < need as u64 {
        return Err(Failure::length(format!(
            "output buffer {what} has length {len}, needs {need}"
        )));
    }
    // SAFETY: non-NULL and valid for `len ≥ need` writes by the caller's contract.
    Ok(Some(unsafe { std::slice::from_raw_parts_mut(ptr, need) }))
}

/// Writes `value` through an optional output pointer.
///
/// # Safety
/// `ptr` is NULL or valid for one write.
pub(crate) unsafe fn put<T>(ptr: *mut T, value: T) {
    if !ptr.is_null() {
        // SAFETY: non-NULL and valid by the caller's contract.
        unsafe { ptr.write(value) }
    }
}
