//! Errors from loading a scene. Every one names the file and either a `line:column`
//! (syntax) or a field path such as `mirrors[1].normal` (meaning), and says what is allowed.

use std::fmt;
use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file could not be read at all.
    #[error("{file}: {message}")]
    Read { file: PathBuf, message: String },
    /// Not valid JSON, or a value of the wrong type / an unknown field.
    #[error("{file}:{line}:{column}: {}{message}", path_prefix(path))]
    Syntax {
        file: PathBuf,
        line: usize,
        column: usize,
        /// The field path where serde stopped, if known (e.g. `mirrors[0].width`).
        path: Option<String>,
        message: String,
    },
    /// Valid JSON whose meaning is not allowed (a degenerate mirror, a NaN, ...).
    #[error("{file}: {path}: {message}")]
    Invalid {
        file: PathBuf,
        path: String,
        message: String,
    },
}

fn path_prefix(path: &Option<String>) -> String {
    match path {
        Some(p) if !p.is_empty() && p != "." => format!("{p}: "),
        _ => String::new(),
    }
}

/// A field path under construction, e.g. `objects[2].transform.scale`.
#[derive(Clone, Debug, Default)]
pub struct FieldPath(String);

impl FieldPath {
    pub fn root(name: &str) -> Self {
        FieldPath(name.to_string())
    }
    pub fn field(&self, name: &str) -> Self {
        if self.0.is_empty() {
            FieldPath(name.to_string())
        } else {
            FieldPath(format!("{}.{name}", self.0))
        }
    }
    pub fn index(&self, i: usize) -> Self {
        FieldPath(format!("{}[{i}]", self.0))
    }
}

impl fmt::Display for FieldPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}
