//! The boundary between C and Rust: panic containment, pointer and string checks, handle
//! publication and the loaders' error-message buffer. Every entry point goes through these.

use std::ffi::{CStr, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

use crate::status::{
    DEFLECT_ERR_INVALID_ARGUMENT, DEFLECT_ERR_NULL, DEFLECT_ERR_PANIC, DEFLECT_OK, DeflectStatus,
};

/// Runs `f`, turning a panic into `DEFLECT_ERR_PANIC`. The closures only touch the caller's
/// pointers and handles; after a panic the handle is still a valid (if partly updated) object,
/// so asserting unwind safety is sound.
#[inline(always)]
pub(crate) fn guard(f: impl FnOnce() -> Result<(), DeflectStatus>) -> DeflectStatus {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => DEFLECT_OK,
        Ok(Err(status)) => status,
        Err(_) => DEFLECT_ERR_PANIC,
    }
}

/// `Some(&[T])` of `len` elements at `ptr`, or `Err(DEFLECT_ERR_NULL)` for NULL.
///
/// # Safety
/// A non-null `ptr` must point to `len` initialised, readable `T` valid for `'a`.
#[inline(always)]
pub(crate) unsafe fn slice<'a, T>(ptr: *const T, len: usize) -> Result<&'a [T], DeflectStatus> {
    if ptr.is_null() {
        return Err(DEFLECT_ERR_NULL);
    }
    // SAFETY: non-null, and the caller guarantees `len` readable elements.
    Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
}

/// Reads `N` doubles at `ptr`.
///
/// # Safety
/// A non-null `ptr` must point to `N` readable doubles.
#[inline(always)]
pub(crate) unsafe fn array<const N: usize>(ptr: *const f64) -> Result<[f64; N], DeflectStatus> {
    if ptr.is_null() {
        return Err(DEFLECT_ERR_NULL);
    }
    let mut out = [0.0; N];
    // SAFETY: non-null, the caller guarantees `N` readable doubles; `out` is a distinct local.
    unsafe { std::ptr::copy_nonoverlapping(ptr, out.as_mut_ptr(), N) };
    Ok(out)
}

/// A mutable slice of `len` elements at `ptr`, or `Err(DEFLECT_ERR_NULL)` for NULL.
///
/// # Safety
/// A non-null `ptr` must point to `len` writable `T` not aliased during `'a`.
#[inline(always)]
pub(crate) unsafe fn slice_mut<'a, T>(
    ptr: *mut T,
    len: usize,
) -> Result<&'a mut [T], DeflectStatus> {
    if ptr.is_null() {
        return Err(DEFLECT_ERR_NULL);
    }
    // SAFETY: non-null, and the caller guarantees `len` writable, unaliased elements.
    Ok(unsafe { std::slice::from_raw_parts_mut(ptr, len) })
}

/// A shared reference to the handle at `ptr`, or `Err(DEFLECT_ERR_NULL)`.
///
/// # Safety
/// A non-null `ptr` must come from this library's constructor and not be destroyed.
#[inline(always)]
pub(crate) unsafe fn handle<'a, T>(ptr: *const T) -> Result<&'a T, DeflectStatus> {
    // SAFETY: the caller guarantees a live handle (or NULL, handled by `as_ref`).
    unsafe { ptr.as_ref() }.ok_or(DEFLECT_ERR_NULL)
}

/// A mutable reference to the handle at `ptr`, or `Err(DEFLECT_ERR_NULL)`.
///
/// # Safety
/// A non-null `ptr` must come from this library's constructor, not be destroyed and not be in
/// use by another thread.
#[inline(always)]
pub(crate) unsafe fn handle_mut<'a, T>(ptr: *mut T) -> Result<&'a mut T, DeflectStatus> {
    // SAFETY: the caller guarantees a live, unshared handle (or NULL, handled by `as_mut`).
    unsafe { ptr.as_mut() }.ok_or(DEFLECT_ERR_NULL)
}

/// Writes `value` to `out`, or fails with `DEFLECT_ERR_NULL`.
///
/// # Safety
/// A non-null `out` must be valid for a write of `T`.
#[inline(always)]
pub(crate) unsafe fn write<T>(out: *mut T, value: T) -> Result<(), DeflectStatus> {
    if out.is_null() {
        return Err(DEFLECT_ERR_NULL);
    }
    // SAFETY: non-null and, by the caller's contract, writable; `write` drops nothing old.
    unsafe { out.write(value) };
    Ok(())
}

/// Copies `msg` into the caller's buffer, truncated at a character boundary so that it fits
/// with its terminating NUL. Does nothing for a NULL buffer or a zero length.
///
/// # Safety
/// A non-null `buf` must be writable for `len` bytes.
pub(crate) unsafe fn write_message(buf: *mut c_char, len: usize, msg: &str) {
    if buf.is_null() || len == 0 {
        return;
    }
    let mut n = msg.len().min(len - 1);
    while !msg.is_char_boundary(n) {
        n -= 1;
    }
    // SAFETY: `buf` holds `len` writable bytes and `n + 1 <= len`; `msg` is a distinct Rust
    // string, so the regions do not overlap.
    unsafe {
        std::ptr::copy_nonoverlapping(msg.as_ptr(), buf.cast::<u8>(), n);
        buf.add(n).write(0);
    }
}

/// Reads a NUL-terminated UTF-8 string.
///
/// # Safety
/// A non-null `ptr` must point to a NUL-terminated string valid for `'a`.
pub(crate) unsafe fn c_str<'a>(
    ptr: *const c_char,
    what: &str,
) -> Result<&'a str, (DeflectStatus, String)> {
    if ptr.is_null() {
        return Err((DEFLECT_ERR_NULL, format!("{what} is NULL")));
    }
    // SAFETY: non-null and NUL-terminated by the caller's contract.
    let s = unsafe { CStr::from_ptr(ptr) };
    s.to_str().map_err(|e| {
        (
            DEFLECT_ERR_INVALID_ARGUMENT,
            format!("{what} is not UTF-8: {e}"),
        )
    })
}

/// Boxes `value` into `*out`.
///
/// # Safety
/// `out` must be non-null (checked by the caller) and writable.
pub(crate) unsafe fn publish<T>(out: *mut *mut T, value: T) {
    // SAFETY: checked non-null by every caller before any work; writable by contract.
    unsafe { out.write(Box::into_raw(Box::new(value))) };
}

/// Frees a handle made by `publish`.
///
/// # Safety
/// `ptr` is NULL or a live handle from `publish`, not used afterwards.
pub(crate) unsafe fn destroy<T>(ptr: *mut T) {
    if !ptr.is_null() {
        // SAFETY: `ptr` came from `Box::into_raw` in `publish` and is freed once.
        drop(unsafe { Box::from_raw(ptr) });
    }
}

/// A loader's common frame: NULL checks, `*out = NULL` first, the message on error.
///
/// # Safety
/// `out` is NULL or writable; `err` is NULL or writable for `err_len` bytes.
pub(crate) unsafe fn load<T>(
    out: *mut *mut T,
    err: *mut c_char,
    err_len: usize,
    f: impl FnOnce() -> Result<T, (DeflectStatus, String)>,
) -> DeflectStatus {
    let mut message = None;
    let status = guard(|| {
        if out.is_null() {
            message = Some("the output handle pointer is NULL".to_owned());
            return Err(DEFLECT_ERR_NULL);
        }
        // SAFETY: `out` is non-null and writable by the caller's contract.
        unsafe { out.write(std::ptr::null_mut()) };
        match f() {
            Ok(value) => {
                // SAFETY: `out` checked non-null above.
                unsafe { publish(out, value) };
                Ok(())
            }
            Err((status, msg)) => {
                message = Some(msg);
                Err(status)
            }
        }
    });
    let msg = match (&message, status) {
        (Some(m), _) => m.as_str(),
        (None, DEFLECT_ERR_PANIC) => "internal error: a panic was caught (please report it)",
        (None, _) => "",
    };
    // SAFETY: `err` is NULL or writable for `err_len` bytes by the caller's contract.
    unsafe { write_message(err, err_len, msg) };
    status
}

/// [`load`] of a handle built by `make` from the C string `arg` (JSON or CSV text, or a file's
/// path), named `what` in the error for a NULL or non-UTF-8 string: what the loaders from
/// text and from a path share.
///
/// # Safety
/// `arg` is NULL or NUL-terminated; `out` is NULL or writable; `err` is NULL or writable for
/// `err_len` bytes.
pub(crate) unsafe fn load_str<T>(
    arg: *const c_char,
    what: &'static str,
    out: *mut *mut T,
    err: *mut c_char,
    err_len: usize,
    make: impl FnOnce(&str) -> Result<T, (DeflectStatus, String)>,
) -> DeflectStatus {
    let make = || {
        // SAFETY: NULL or NUL-terminated by the caller's contract.
        let s = unsafe { c_str(arg, what) }?;
        make(s)
    };
    // SAFETY: forwarded caller contract.
    unsafe { load(out, err, err_len, make) }
}

/// Always unwinds (panics) inside Rust and returns `DEFLECT_ERR_PANIC`: lets a C caller check
/// that panics are contained at the boundary. Prints nothing.
#[unsafe(no_mangle)]
pub extern "C" fn deflect_test_panic() -> DeflectStatus {
    guard(|| {
        std::panic::resume_unwind(Box::new("deflect_test_panic: deliberate panic"));
    })
}
