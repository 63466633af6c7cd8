//! A refusal of the command line itself (flags that do not go together, a flag the chosen model
//! does not use): the binary exits with its usage code (2, docs/console.md "Exit codes") for
//! these, as for clap's own, and with 1 for a value the model refuses.

/// The command line is wrong, said in words (what, which value, what to do).
#[derive(Debug)]
pub struct Usage(pub String);

impl std::fmt::Display for Usage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Usage {}

/// `Err` of a [`Usage`] with these words.
pub fn usage<T>(words: impl Into<String>) -> anyhow::Result<T> {
    Err(Usage(words.into()).into())
}
