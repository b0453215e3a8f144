//! Printing to stdout for both programs, never a panic: a reader that went away (a
//! closed pipe, `| head`) ends the output quietly — later prints are skipped and the
//! command ends with the status it would have had — while any other failure (`>
//! /dev/full`) is a [`CannotWrite`] naming `stdout` (exit [`crate::fsio::EXIT_CANNOT_WRITE`]).

use crate::fsio::CannotWrite;
use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

static CLOSED: AtomicBool = AtomicBool::new(false);

/// `eprintln!` that never panics: a message for stderr, dropped when stderr cannot take
/// it (`2> /dev/full`, a closed pipe) instead of aborting the command.
#[macro_export]
macro_rules! note {
    ($($arg:tt)*) => {{
        use ::std::io::Write as _;
        let _ = ::std::writeln!(::std::io::stderr(), $($arg)*);
    }};
}

/// `eprint!` that never panics (see [`note!`]).
#[macro_export]
macro_rules! note_part {
    ($($arg:tt)*) => {{
        use ::std::io::Write as _;
        let _ = ::std::write!(::std::io::stderr(), $($arg)*);
    }};
}

/// Writes `text` to stdout and flushes it.
pub fn print(text: &str) -> Result<(), CannotWrite> {
    write_to(&mut std::io::stdout().lock(), text.as_bytes())
}

/// `text` and a newline.
pub fn println(text: &str) -> Result<(), CannotWrite> {
    let mut line = String::with_capacity(text.len() + 1);
    line.push_str(text);
    line.push('\n');
    print(&line)
}

/// Whether a reader closed stdout (what was printed after it went nowhere).
pub fn closed() -> bool {
    CLOSED.load(Ordering::Relaxed)
}

fn write_to(out: &mut impl Write, bytes: &[u8]) -> Result<(), CannotWrite> {
    if closed() {
        return Ok(());
    }
    match out.write_all(bytes).and_then(|_| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {
            CLOSED.store(true, Ordering::Relaxed);
            Ok(())
        }
        Err(e) => Err(CannotWrite::new("", Path::new("stdout"), e)),
    }
}

/// The arguments with `help --help` (or `-h`) read as `help`: the help of the
/// command-line parser's `help` subcommand takes no flags, and asking for its help is
/// asking for help.
pub fn help_help_as_help(args: Vec<std::ffi::OsString>) -> Vec<std::ffi::OsString> {
    if args.get(1).is_some_and(|a| a == "help") {
        let mut out = args;
        let tail: Vec<_> = out
            .drain(2..)
            .filter(|a| a != "--help" && a != "-h")
            .collect();
        out.extend(tail);
        out
    } else {
        args
    }
}

/// The exit status after printing the parser's help, version or usage error with
/// `print`: its own `code`, or [`crate::fsio::EXIT_CANNOT_WRITE`] when stdout could not
/// take it (a closed pipe aside), with a message.
pub fn parser_print_status(code: i32, print: std::io::Result<()>, program: &str) -> u8 {
    match print {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            crate::note!("{program}: cannot write stdout: {e}");
            crate::fsio::EXIT_CANNOT_WRITE
        }
        _ => u8::try_from(code).unwrap_or(2),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Failing(std::io::ErrorKind);
    impl Write for Failing {
        fn write(&mut self, _: &[u8]) -> std::io::Result<usize> {
            Err(self.0.into())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn a_full_stdout_is_an_error_and_a_closed_one_ends_quietly() {
        let e = write_to(&mut Failing(std::io::ErrorKind::StorageFull), b"x").unwrap_err();
        assert!(e.to_string().starts_with("cannot write stdout: "), "{e}");
        assert!(!e.to_string().contains("previous file"), "{e}");
        assert!(!closed());
        write_to(&mut Failing(std::io::ErrorKind::BrokenPipe), b"x").unwrap();
        assert!(closed());
        // Once closed, nothing more is tried.
        write_to(&mut Failing(std::io::ErrorKind::StorageFull), b"x").unwrap();
    }

    #[test]
    fn help_help_is_help() {
        let a = |v: &[&str]| v.iter().map(std::ffi::OsString::from).collect::<Vec<_>>();
        assert_eq!(
            help_help_as_help(a(&["p", "help", "--help"])),
            a(&["p", "help"])
        );
        assert_eq!(
            help_help_as_help(a(&["p", "help", "build", "-h"])),
            a(&["p", "help", "build"])
        );
        assert_eq!(
            help_help_as_help(a(&["p", "build", "--help"])),
            a(&["p", "build", "--help"])
        );
    }
}
