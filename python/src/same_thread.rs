//! Carrying thread-bound values into `Python::allow_threads`.

/// A value moved into a closure that `Python::allow_threads` runs on the current thread.
///
/// `allow_threads` only asks for `Send` so that nothing GIL-bound leaks into code running
/// without the GIL; it runs the closure on the calling thread. symx expressions are
/// `!Send` because they index the calling thread's graph, which therefore stays valid
/// for the closure. Wrap only values that are used inside the closure and nowhere else.
pub struct SameThread<T>(pub T);

// SAFETY: only used for closures passed to `Python::allow_threads`, which executes them
// synchronously on the thread that owns the wrapped value (see the type's doc).
unsafe impl<T> Send for SameThread<T> {}
