//! Surface containers written by contactscope (`surface --out x.zip`, `simulate --export
//! surface-container`): contact.engineering's container layout
//! ([`contactscope_formats::topography::container_write`]), with contactscope's version and
//! source revision in the metadata and a `README.txt` in our words.

use std::path::Path;

use contactscope_formats::topography::container_write::ContainerBuilder;

use crate::error::{Error, Result};
use crate::staging::Staging;

fn readme(what: &str) -> String {
    format!(
        "Contents of this ZIP archive
============================
A surface container in the layout of contact.engineering and SurfaceTopography
(SurfaceTopography.read_container reads it), written by contactscope {}.

{what}

index.json and meta.yml hold the same metadata (surfaces, their topographies, each
topography's data file, physical size and unit, periodicity). Each topography is a NetCDF
file topography<N>.nc with the variable heights(x, y) in metres (x first), the coordinate
variables x and y with their length, and the topography's description as JSON in the global
attribute json.
",
        crate::provenance::version()
    )
}

fn versions() -> Vec<(&'static str, &'static str)> {
    let mut v = vec![("contactscope", crate::provenance::version())];
    if let Some(r) = crate::provenance::source_revision() {
        v.push(("contactscope source revision", r));
    }
    v
}

fn now() -> String {
    crate::provenance::rfc3339(std::time::SystemTime::now())
}

/// Write the container to `path` atomically (a temporary file beside it, then a rename).
pub fn write_container(path: &Path, builder: ContainerBuilder, what: &str) -> Result<()> {
    let cursor = builder.write_to(
        std::io::Cursor::new(Vec::new()),
        &versions(),
        &now(),
        &readme(what),
    )?;
    crate::staging::write_atomic(path, &cursor.into_inner())
}

/// Stage the container as output file `name`, written straight to the staged file.
pub fn stage_container(
    staging: &Staging,
    name: &str,
    builder: ContainerBuilder,
    what: &str,
) -> Result<()> {
    staging.write_with(name, |file| {
        builder
            .write_to(file, &versions(), &now(), &readme(what))
            .map(|_| ())
            .map_err(Error::from)
    })?;
    Ok(())
}
