//! Printing to standard output that ends the program quietly when the reader has gone
//! (output piped into `head`), where the standard macros panic.

/// `println!` that ends the program quietly when standard output has been closed.
macro_rules! println {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = writeln!(std::io::stdout().lock(), $($t)*) {
            $crate::output::closed_stdout(e)
        }
    }};
}

/// `print!` with [`println!`]'s handling of a closed standard output.
macro_rules! print {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = write!(std::io::stdout().lock(), $($t)*) {
            $crate::output::closed_stdout(e)
        }
    }};
}

/// A reader that stopped reading (a closed pipe) ends the run successfully; any other
/// failure to write the output is an error.
pub fn closed_stdout(e: std::io::Error) -> ! {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        std::process::exit(0)
    }
    eprintln!("cadmorph: writing the output: {e}");
    std::process::exit(1)
}
