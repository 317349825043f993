//! Build script of the command line: records the source revision (`crates/jobs/build/revision.rs`).

include!("crates/jobs/build/revision.rs");

fn main() {
    emit_source_revision(".");
}
