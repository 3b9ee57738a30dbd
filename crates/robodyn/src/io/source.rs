//! Positions in source files: the line index of a text and the map from description items to
//! their lines, shared by the readers.

use crate::error::{Error, Item};
use crate::io::Warning;
use std::collections::HashMap;

/// Byte offsets of the line starts of a text: line and column of an offset in O(log n), so
/// that a reader placing every value stays linear in the file size.
#[derive(Clone, Debug)]
pub struct LineIndex {
    starts: Vec<usize>,
    len: usize,
}

impl LineIndex {
    /// Index the lines of `text`.
    pub fn new(text: &str) -> LineIndex {
        let starts = std::iter::once(0)
            .chain(
                text.bytes()
                    .enumerate()
                    .filter(|(_, b)| *b == b'\n')
                    .map(|(i, _)| i + 1),
            )
            .collect();
        LineIndex {
            starts,
            len: text.len(),
        }
    }

    /// 1-based line of a byte offset (offsets past the end are on the last line).
    pub fn line(&self, offset: usize) -> usize {
        self.starts.partition_point(|&s| s <= offset.min(self.len))
    }

    /// 1-based line and column (in bytes) of a byte offset.
    pub fn position(&self, offset: usize) -> (usize, usize) {
        let offset = offset.min(self.len);
        let line = self.line(offset);
        (line, offset - self.starts[line - 1] + 1)
    }

    /// Byte offset of the start of a 1-based line.
    pub fn line_start(&self, line: usize) -> usize {
        self.starts[line.clamp(1, self.starts.len()) - 1]
    }
}

/// Line numbers of the items of a file, to place errors found after parsing, and the warnings
/// of the reader.
#[derive(Default, Debug, Clone)]
pub struct SourceMap {
    /// The file, for messages.
    pub file: Option<String>,
    lines: HashMap<ItemKey, usize>,
    /// What the reader (and the loader's physical-consistency check) noticed, in file order.
    pub warnings: Vec<Warning>,
}

#[derive(Hash, PartialEq, Eq, Debug, Clone)]
enum ItemKey {
    Frame(usize, Option<String>),
    Link(usize, Option<String>),
    Base(String),
    Symbol(String),
}

impl SourceMap {
    /// An empty map for `file`.
    pub fn new(file: Option<&str>) -> SourceMap {
        SourceMap {
            file: file.map(str::to_string),
            ..Default::default()
        }
    }

    /// Record the line of frame j, optionally one of its parameters.
    pub fn set_frame(&mut self, j: usize, param: Option<&str>, line: usize) {
        self.lines
            .insert(ItemKey::Frame(j, param.map(str::to_string)), line);
    }
    /// Record the line of link j, optionally one of its parameters.
    pub fn set_link(&mut self, j: usize, param: Option<&str>, line: usize) {
        self.lines
            .insert(ItemKey::Link(j, param.map(str::to_string)), line);
    }
    /// Record the line of a base quantity (`G`, `W0`, `assembly`...).
    pub fn set_base(&mut self, name: &str, line: usize) {
        self.lines.insert(ItemKey::Base(name.to_string()), line);
    }
    /// Record the line of a symbol's value.
    pub fn set_symbol(&mut self, name: &str, line: usize) {
        self.lines.insert(ItemKey::Symbol(name.to_string()), line);
    }

    /// The line of an item, falling back to its frame/link as a whole.
    pub fn line_of(&self, item: &Item) -> Option<usize> {
        let get = |k: ItemKey| self.lines.get(&k).copied();
        match item {
            Item::Frame(j, p) => {
                get(ItemKey::Frame(*j, p.clone())).or(get(ItemKey::Frame(*j, None)))
            }
            Item::Link(j, p) => get(ItemKey::Link(*j, p.clone())).or(get(ItemKey::Link(*j, None))),
            Item::Base(n) => {
                let base = n.split('[').next().unwrap_or(n).to_string();
                get(ItemKey::Base(base))
            }
            Item::Symbol(s) => get(ItemKey::Symbol(s.clone())),
            Item::Robot | Item::Loop(_) => None,
        }
    }

    /// Record a warning, with the file and the line of its item when they are known.
    pub fn warn(&mut self, mut w: Warning) {
        if w.location.file.is_none() {
            w.location.file = self.file.clone();
        }
        if w.location.line.is_none() {
            w.location.line = w.item.as_ref().and_then(|i| self.line_of(i));
        }
        self.warnings.push(w);
    }

    /// Attach file and line to an error.
    pub fn locate(&self, e: Error) -> Error {
        let line = e.item().and_then(|i| self.line_of(i));
        e.at(self.file.as_deref(), line)
    }
}
