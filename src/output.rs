//! Standard output of the commands (`info`, `bench`, `paper`): every line
//! goes through [`write_line`] (the `outln!` macro), which
//! treats a reader that went away as the end of the command, as coreutils
//! do under SIGPIPE.
//!
//! Rust ignores SIGPIPE, so a write to a closed pipe (`volray info F |
//! head -1`) fails with `BrokenPipe`, on which `println!` panics (exit
//! 101). Here it ends the process with exit 0: nobody is reading any more,
//! and the command did nothing wrong. Any other failure to write (a full
//! disk behind a redirection) ends it with exit 2, an I/O failure. Either
//! way the temporary files of outputs still being written are deleted
//! first, since `exit` runs no destructors.

use std::fmt;
use std::io::{self, Write};

/// Prints one line to standard output through [`write_line`]. `main.rs`
/// declares this module first, with `#[macro_use]`, so every module has it.
macro_rules! outln {
    () => {
        $crate::output::write_line(format_args!(""))
    };
    ($($arg:tt)*) => {
        $crate::output::write_line(format_args!($($arg)*))
    };
}

/// Writes `line` and a newline to standard output, flushed; ends the
/// process if standard output cannot take it (see the module docs).
pub fn write_line(line: fmt::Arguments) {
    if let Err(e) = write_to(&mut io::stdout().lock(), line) {
        end_on_write_error(&e);
    }
}

fn write_to(out: &mut impl Write, line: fmt::Arguments) -> io::Result<()> {
    out.write_fmt(line)?;
    out.write_all(b"\n")?;
    out.flush()
}

/// The exit code for a failure to write standard output: 0 when the reader
/// closed the pipe, 2 otherwise.
fn exit_code(e: &io::Error) -> i32 {
    if e.kind() == io::ErrorKind::BrokenPipe {
        0
    } else {
        2
    }
}

fn end_on_write_error(e: &io::Error) -> ! {
    let code = exit_code(e);
    if code != 0 {
        eprintln!("volray: error: cannot write to standard output: {e}");
    }
    volray_io::remove_unfinished_files();
    std::process::exit(code)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A writer that fails every write with `kind`.
    struct Failing(io::ErrorKind);

    impl Write for Failing {
        fn write(&mut self, _: &[u8]) -> io::Result<usize> {
            Err(io::Error::from(self.0))
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn lines_end_with_a_newline() {
        let mut buf = Vec::new();
        write_to(&mut buf, format_args!("a {}", 1)).unwrap();
        write_to(&mut buf, format_args!("")).unwrap();
        assert_eq!(buf, b"a 1\n\n");
    }

    #[test]
    fn a_closed_pipe_is_success_and_other_failures_are_io_errors() {
        let e = write_to(&mut Failing(io::ErrorKind::BrokenPipe), format_args!("x")).unwrap_err();
        assert_eq!(exit_code(&e), 0);
        let e = write_to(&mut Failing(io::ErrorKind::StorageFull), format_args!("x")).unwrap_err();
        assert_eq!(exit_code(&e), 2);
    }
}
