//! The `cadmorph` command-line tool.
fn main() {}
