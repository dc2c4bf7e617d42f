//! Benchmark support (feature `bench-internals`, not part of the stable API): the
//! tokenizer of the Parameter Data section timed alone, without the line split, the
//! Directory Entry section, the checks and the building of the document.

use crate::document::Document;
use crate::error::Result;
use crate::read::lexer::{tokenize_record_one_thread, RecordLines};
use crate::read::P_WIDTH;

/// The parameter records of a parsed document, ready to be tokenized again.
pub struct ParameterRecords {
    doc: Document,
}

impl ParameterRecords {
    /// Parses `bytes` (the whole file) once; [`tokenize`](Self::tokenize) then re-reads
    /// the records of its entities.
    ///
    /// # Errors
    ///
    /// Those of [`Document::from_bytes`].
    pub fn new(bytes: Vec<u8>) -> Result<Self> {
        Ok(Self { doc: Document::from_bytes(bytes)? })
    }

    /// Bytes of parameter text the records cover (64 data columns per P line).
    pub fn parameter_bytes(&self) -> usize {
        self.doc.entities.iter().map(|e| e.p_count * P_WIDTH).sum()
    }

    /// Tokenizes every entity's parameter record on the calling thread, as the reader
    /// does with one thread (records of more than 64 lines through a 64-line window, no
    /// parallel cut), and returns the number of tokens (`None` if a record does not read,
    /// which a parsed document's records always do).
    pub fn tokenize(&self) -> Option<usize> {
        let src = &self.doc.src;
        let p0 = self.doc.layout.parameter.start;
        let mut tokens = 0;
        for e in &self.doc.entities {
            let (pd, rd) = e.delimiters;
            let lines = &src.lines[p0 + e.p_first..p0 + e.p_first + e.p_count];
            let rec = RecordLines { bytes: &src.bytes, lines, width: P_WIDTH };
            tokens += tokenize_record_one_thread(&rec, pd, rd).ok()?.tokens.len();
        }
        Some(tokens)
    }
}
