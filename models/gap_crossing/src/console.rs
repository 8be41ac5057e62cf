//! The command line's log, best effort: a closed pipe (`gap-crossing | head`) or a failing
//! terminal never stops a run. Rust's `println!` panics when standard output is gone, which
//! would end a solve before its files are written; these macros drop what cannot be
//! printed instead, and the run goes on to its files and its exit code.

use std::fmt::Arguments;
use std::io::Write;

/// Writes to standard output, ignoring a failure (use [`outln!`](crate::outln)).
#[doc(hidden)]
pub fn write_out(args: Arguments<'_>) {
    let _ = std::io::stdout().lock().write_fmt(args);
}

/// Writes to standard error, ignoring a failure (use [`errln!`](crate::errln)).
#[doc(hidden)]
pub fn write_err(args: Arguments<'_>) {
    let _ = std::io::stderr().lock().write_fmt(args);
}

/// `print!` that never panics ([`crate::console`]).
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::console::write_out(format_args!($($arg)*))
    };
}

/// `println!` that never panics ([`crate::console`]).
#[macro_export]
macro_rules! outln {
    () => {
        $crate::console::write_out(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::console::write_out(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `eprintln!` that never panics ([`crate::console`]).
#[macro_export]
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::console::write_err(format_args!("{}\n", format_args!($($arg)*)))
    };
}
