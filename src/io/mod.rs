//! Readers and writers of model files. Readers turn bytes into a validated [`TMesh`](crate::tmesh::TMesh)
//! wrapped in a [`Model`]; they never evaluate the surface themselves.
//!
//! Formats: the project's JSON T-mesh ([`json`]) and Autodesk T-Splines `.tsm` files
//! ([`tsm`]). The format is detected from the content, not from a file name, so the page and
//! the CLI accept the same bytes.

pub mod export;
pub mod json;
pub mod obj;
pub mod tsm;

use crate::error::{Error, Result};
use crate::model::setup::ImportSetup;
use crate::model::Model;

/// Model file formats the readers know.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Json,
    Tsm,
    Obj,
}

impl Format {
    /// Short lower-case name (`json`, `tsm`, `obj`).
    pub fn name(self) -> &'static str {
        match self {
            Format::Json => "json",
            Format::Tsm => "tsm",
            Format::Obj => "obj",
        }
    }
}

/// Guesses the format from the first meaningful bytes.
pub fn detect(bytes: &[u8]) -> Result<Format> {
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .ok_or_else(|| {
            Error::parse(
                "model",
                "byte 0",
                "the file is empty or holds only whitespace",
            )
        })?;
    let head = &bytes[start..];
    if head.starts_with(b"{") {
        Ok(Format::Json)
    } else if head.starts_with(b"#TS") {
        Ok(Format::Tsm)
    } else if head
        .split(|&b| b == b'\n')
        .take(200)
        .any(|l| l.starts_with(b"v ") || l.starts_with(b"f "))
    {
        Ok(Format::Obj)
    } else {
        Err(Error::parse(
            "model",
            "start of file",
            "not a model file this program knows (expected JSON T-mesh, .tsm or .obj)",
        ))
    }
}

/// Reads a model from bytes, format detected from the content. `name` is used when the
/// file carries no name of its own.
pub fn load(bytes: &[u8], name: &str) -> Result<Model> {
    load_with(bytes, name, &ImportSetup::default())
}

/// As [`load`], the model placed by `setup` (unit for files that do not say, scale, up
/// axis, turn, on the table).
pub fn load_with(bytes: &[u8], name: &str, setup: &ImportSetup) -> Result<Model> {
    setup.validate()?;
    match detect(bytes)? {
        Format::Json => {
            let text = std::str::from_utf8(bytes).map_err(|e| {
                Error::parse(
                    "json",
                    format!("byte {}", e.valid_up_to()),
                    "the file is not UTF-8 text",
                )
            })?;
            let (mesh, meta) = json::read(text)?;
            let name = if meta.name.is_empty() {
                name
            } else {
                &meta.name
            };
            let declared = json::unit_scale(&meta.units);
            Model::try_new_placed(name, "json", &meta.units, mesh, setup, declared)
        }
        Format::Obj => {
            let text = String::from_utf8_lossy(bytes);
            // The unit set for the file wins; else the one its header comment names (Maya's
            // export, OpenSubdiv's shapes); else mm.
            let (units, setup) = match setup.model_units {
                Some(u) => (u.name().to_string(), *setup),
                None => match obj::unit_comment(&text) {
                    Some(u) => (
                        format!("{} (the file's header comment)", u.name()),
                        ImportSetup {
                            model_units: Some(u),
                            ..*setup
                        },
                    ),
                    None => ("mm (assumed)".to_string(), *setup),
                },
            };
            let (mesh, warnings) = obj::read(&text)?;
            let mut m = Model::try_new_placed(name, "obj", &units, mesh, &setup, None)?;
            m.warnings = warnings;
            Ok(m)
        }
        Format::Tsm => {
            let (mesh, meta) = tsm::read(bytes)?;
            let declared = Some(meta.metres_per_unit * 1000.0);
            Model::try_new_placed(name, "tsm", &meta.units_label(), mesh, setup, declared)
        }
    }
}
