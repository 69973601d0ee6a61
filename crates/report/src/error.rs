//! The error of reading reports: a message naming the file and what is wrong.

/// Why the README's regions could not be generated or filled.
#[derive(Debug, PartialEq)]
pub struct ReadmeError(pub String);

impl std::fmt::Display for ReadmeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}
