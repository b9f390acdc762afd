//! Values a user picks by name from a fixed list (`--preset`, `--order`, `--format`,
//! `--arrangement`): their names and one-line help live with the types, in the libraries, so
//! that the command line (`src/cli`) offers them without a library depending on an argument
//! parser. Here, in the lowest crate, so that every crate's types can have names.

/// A closed set of values, each with the name a user types and a line of help.
pub trait Named: Copy + Send + Sync + 'static {
    /// Every value, in the order `--help` lists them.
    const ALL: &'static [Self];

    /// The value's name on the command line and in records.
    fn name(self) -> &'static str;

    /// One line for `--help`.
    fn help(self) -> &'static str;

    /// The value named `name`, if any.
    fn from_name(name: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|v| v.name() == name)
    }
}
