//! The CLI's error is the door's: a one-line message whose kind decides
//! the exit code, one mapping for every verb (`tricept_ident::Error`).

pub use tricept_ident::{EXIT_OTHER, Error as CliError};
