//! Failures of a command, each one line, and the exit code it maps to:
//! 0 success, 1 bad input or arguments, 2 I/O failure.

use std::fmt;

#[derive(Debug)]
pub struct CliError {
    pub code: u8,
    pub message: String,
}

impl CliError {
    /// Bad input or arguments: exit code 1.
    pub fn input(message: impl Into<String>) -> Self {
        CliError {
            code: 1,
            message: message.into(),
        }
    }

    /// The operating system failed to read or write: exit code 2.
    pub fn io(message: impl Into<String>) -> Self {
        CliError {
            code: 2,
            message: message.into(),
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl From<volray_io::IoError> for CliError {
    fn from(e: volray_io::IoError) -> Self {
        if e.is_io_failure() {
            CliError::io(e.to_string())
        } else {
            CliError::input(e.to_string())
        }
    }
}

impl From<volray_data::DataError> for CliError {
    fn from(e: volray_data::DataError) -> Self {
        CliError::input(e.to_string())
    }
}
