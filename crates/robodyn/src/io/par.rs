//! SYMORO's `.par` robot files, read and written.
//!
//! The dialect accepted (see `docs/robot-format.md`):
//! - `(* comments *)`, possibly spanning lines;
//! - `NL NJ NF Type is_mobile is_floating` scalars (`NF` must equal 2 NJ - NL; `is_mobile` and
//!   `is_floating` are 0/1 or OpenSYMORO's Python booleans `True`/`False`);
//! - lists `{a, b, ...}` of NF entries: `ant sigma b d r gamma alpha mu theta` (SYMORO+'s
//!   capitalised `Ant Mu Sigma B Alpha Theta R` too; keys are case-insensitive);
//! - lists of NL entries: `XX XY XZ YY YZ ZZ MX MY MZ M IA FV FS FX FY FZ CX CY CZ`;
//! - lists of NJ entries `QP QDP GAM` (symbolic joint velocities etc., checked and ignored);
//! - `W0 WP0 V0 VP0 G` of 3 entries (`G` is the gravity acceleration g in frame 0), `Z` of 16;
//! - `Robotname = 'name'` or `name = ...`, also inside a comment as SYMORO writes it.
//!
//! **Joint variables, as SYMORO reads them.** The `theta` entry of a revolute joint (the `r`
//! entry of a prismatic one) *is* the joint variable in SYMORO. robodyn splits it into the
//! variable q_j and a constant offset: the variable is the entry's symbol without a value (a
//! name such as `th3`, `q3`, `t3` when there are several); it must enter with coefficient 1
//! (`th3 + pi/2`); what remains is the offset we store. An entry with no symbol left (a number,
//! a constant expression) is the value SYMORO gives the joint variable, i.e. the configuration
//! the file describes, not an offset: the offset is 0, and a warning says so when the value is
//! not 0.
//!
//! SYMORO files carry no numeric values for their symbols. Our writer stores them in a comment
//! SYMORO ignores, `(* robodyn values: d2 = 0.15; d3 = 0.6 *)`, which our reader reads back (as
//! it does `(* robodyn frame names: ... *)`, `(* robodyn link names: ... *)`,
//! `(* robodyn note: ... *)`, `(* robodyn name: ... *)`, `(* robodyn assembly: ... *)` and the
//! joint limits `(* robodyn limits q_min: 1 = -3.14; ... *)` (likewise `q_max`, `qd`, `qdd`,
//! `tau`, by frame number)), so that `.par -> .toml -> .par` round-trips. A name or note that `;`, a new line, `*` or a quote
//! would break is written as a quoted string with backslash escapes.
//!
//! Reading is linear in the file size: positions come from a [`LineIndex`], and the counts are
//! checked against the lists the file has before anything is sized from them.

use crate::error::{Error, Item, Location, Result};
use crate::io::source::LineIndex;
use crate::io::toml_format::is_symbol_name;
use crate::io::{SourceMap, Warning};
use crate::model::{
    validate_structure, JointType, LinkDesc, RobotDescription, GEOMETRIC_PARAMETERS,
    STANDARD_PARAMETERS, WRENCH_COMPONENTS,
};
use robodyn_symbolic::Expr;
use std::collections::{BTreeMap, BTreeSet};

/// Without lists giving that many entries, a file may not declare more frames than this (a
/// description of NF frames is built before the lists are read).
const FRAMES_WITHOUT_LISTS: usize = 1000;

/// One `KEY = value` statement.
struct Statement {
    key: String,
    /// Byte offset of the key.
    at: usize,
    /// Entries with their byte offsets (one entry for a scalar).
    entries: Vec<(String, usize)>,
    is_list: bool,
}

struct Ctx<'a> {
    text: &'a str,
    file: Option<&'a str>,
    lines: LineIndex,
}

impl Ctx<'_> {
    fn line(&self, offset: usize) -> usize {
        self.lines.line(offset)
    }
    fn err(&self, offset: usize, reason: impl Into<String>) -> Error {
        let (line, col) = self.lines.position(offset);
        Error::Parse {
            location: Location {
                file: self.file.map(str::to_string),
                line: Some(line),
                column: Some(col),
            },
            reason: reason.into(),
        }
    }
    fn err_line(&self, offset: usize, reason: impl Into<String>) -> Error {
        Error::parse(self.file, self.line(offset), reason)
    }
    /// Parse an expression (SYMORO's `Pi` is accepted by the expression parser).
    fn expr(&self, key: &str, s: &str, at: usize) -> Result<Expr> {
        Expr::parse(s).map_err(|e| {
            self.err(
                at + e.offset,
                format!("{key}: bad expression `{s}`: {}", e.message),
            )
        })
    }
}

/// Replace comments by spaces (keeping newlines, so offsets stay valid); return the comments'
/// texts with their offsets.
fn strip_comments(ctx: &Ctx) -> Result<(String, Vec<(String, usize)>)> {
    let b = ctx.text.as_bytes();
    let mut out = b.to_vec();
    let mut comments = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'(' && b.get(i + 1) == Some(&b'*') {
            let start = i;
            let mut depth = 0;
            let mut j = i;
            loop {
                if j + 1 >= b.len() {
                    return Err(ctx.err(start, "comment `(*` is never closed by `*)`"));
                }
                if b[j] == b'(' && b[j + 1] == b'*' {
                    depth += 1;
                    j += 2;
                } else if b[j] == b'*' && b[j + 1] == b')' {
                    depth -= 1;
                    j += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    j += 1;
                }
            }
            comments.push((ctx.text[start + 2..j - 2].to_string(), start + 2));
            for c in out.iter_mut().take(j).skip(start) {
                if *c != b'\n' {
                    *c = b' ';
                }
            }
            i = j;
        } else {
            i += 1;
        }
    }
    // only ASCII bytes were replaced by ASCII spaces at char boundaries of comments
    let s = String::from_utf8(out).map_err(|_| ctx.err(0, "the file is not valid UTF-8"))?;
    Ok((s, comments))
}

fn split_statements(ctx: &Ctx, s: &str) -> Result<Vec<Statement>> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let skip_ws = |i: &mut usize| {
        while *i < b.len() && (b[*i] as char).is_whitespace() {
            *i += 1;
        }
    };
    loop {
        skip_ws(&mut i);
        if i >= b.len() {
            break;
        }
        let key_at = i;
        while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
            i += 1;
        }
        if i == key_at {
            return Err(ctx.err(
                key_at,
                format!("expected `KEY = value`, found `{}`", b[i] as char),
            ));
        }
        let key = s[key_at..i].to_string();
        while i < b.len() && (b[i] == b' ' || b[i] == b'\t') {
            i += 1;
        }
        if i >= b.len() || b[i] != b'=' {
            return Err(ctx.err(i.min(b.len()), format!("expected `=` after `{key}`")));
        }
        i += 1;
        while i < b.len() && (b[i] == b' ' || b[i] == b'\t') {
            i += 1;
        }
        if i < b.len() && b[i] == b'{' {
            let open = i;
            i += 1;
            let mut entries = Vec::new();
            let mut depth = 0i32;
            let mut start = i;
            loop {
                if i >= b.len() {
                    return Err(ctx.err(open, format!("{key}: `{{` is never closed by `}}`")));
                }
                match b[i] {
                    b'(' | b'[' => depth += 1,
                    b')' | b']' => depth -= 1,
                    b'{' => return Err(ctx.err(i, format!("{key}: nested `{{` in a list"))),
                    b',' | b'}' if depth == 0 => {
                        let raw = &s[start..i];
                        let lead = raw.len() - raw.trim_start().len();
                        let t = raw.trim();
                        if t.is_empty() && !(b[i] == b'}' && entries.is_empty()) {
                            return Err(ctx.err(i, format!("{key}: empty list entry")));
                        }
                        if !t.is_empty() {
                            entries.push((t.to_string(), start + lead));
                        }
                        if b[i] == b'}' {
                            i += 1;
                            break;
                        }
                        start = i + 1;
                    }
                    _ => {}
                }
                i += 1;
            }
            out.push(Statement {
                key,
                at: key_at,
                entries,
                is_list: true,
            });
        } else {
            let start = i;
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
            let raw = &s[start..i];
            let t = raw.trim();
            if t.is_empty() {
                return Err(ctx.err(start, format!("{key}: missing value after `=`")));
            }
            out.push(Statement {
                key,
                at: key_at,
                entries: vec![(t.to_string(), start)],
                is_list: false,
            });
        }
    }
    Ok(out)
}

/// What a key is, by its lowercase name.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum KeyKind {
    Count,    // nl nj nf
    Type,     // type
    Flag,     // is_mobile is_floating
    Name,     // robotname, name
    PerFrame, // ant sigma b d r gamma alpha mu theta
    PerLink,  // XX ... CZ
    PerJoint, // QP QDP GAM eta k
    Base,     // W0 WP0 V0 VP0 G
    ZMatrix,  // Z
}

fn key_kind(k: &str) -> Option<KeyKind> {
    Some(match k.to_ascii_lowercase().as_str() {
        "nl" | "nj" | "nf" => KeyKind::Count,
        "type" => KeyKind::Type,
        "is_mobile" | "is_floating" => KeyKind::Flag,
        "robotname" | "name" => KeyKind::Name,
        "ant" | "sigma" | "b" | "d" | "r" | "gamma" | "alpha" | "mu" | "theta" => KeyKind::PerFrame,
        "xx" | "xy" | "xz" | "yy" | "yz" | "zz" | "mx" | "my" | "mz" | "m" | "ia" | "fv" | "fs"
        | "fx" | "fy" | "fz" | "cx" | "cy" | "cz" => KeyKind::PerLink,
        "qp" | "qdp" | "gam" | "eta" | "k" => KeyKind::PerJoint,
        "w0" | "wp0" | "v0" | "vp0" | "g" => KeyKind::Base,
        "z" => KeyKind::ZMatrix,
        _ => return None,
    })
}

/// Whether `name` looks like the variable of joint type `joint` (`th3`, `q3`, `t3`, `theta3`
/// for revolute; `r3`, `q3` for prismatic).
fn is_variable_name(name: &str, joint: JointType) -> bool {
    let lower = name.to_ascii_lowercase();
    let prefixes: &[&str] = match joint {
        JointType::Revolute => &["theta", "th", "q", "t"],
        JointType::Prismatic => &["r", "q"],
        JointType::Fixed => &[],
    };
    prefixes.iter().any(|p| {
        lower
            .strip_prefix(p)
            .is_some_and(|rest| !rest.is_empty() && rest.bytes().all(|c| c.is_ascii_digit()))
    })
}

/// A text for a robodyn comment: as it is when nothing in it can break the comment or its
/// `;`-separated list, else a quoted string with backslash escapes (`\"`, `\\`, `\n`, `\r`,
/// `\t`, and `\x2a` for every `*`, so that neither `(*` nor `*)` appears).
fn comment_text(s: &str) -> String {
    let plain = !s.is_empty()
        && s.trim() == s
        && !s.starts_with('"')
        && !s.contains([';', '\n', '\r', '*', '\\']);
    if plain {
        return s.to_string();
    }
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            '*' => out.push_str("\\x2a"),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The text of a value written by [`comment_text`] (`None` for a broken quoted string).
fn uncomment_text(s: &str) -> Option<String> {
    let Some(body) = s.strip_prefix('"') else {
        return Some(s.to_string());
    };
    let body = body.strip_suffix('"')?;
    let mut out = String::with_capacity(body.len());
    let mut chars = body.chars();
    while let Some(c) = chars.next() {
        match c {
            '\\' => out.push(match chars.next()? {
                'n' => '\n',
                'r' => '\r',
                't' => '\t',
                'x' => {
                    let hex: String = chars.by_ref().take(2).collect();
                    char::from(u8::from_str_radix(&hex, 16).ok().filter(|b| b.is_ascii())?)
                }
                other => other,
            }),
            '"' => return None,
            c => out.push(c),
        }
    }
    Some(out)
}

/// Split the body of a robodyn comment into items at `;` and new lines outside quoted strings,
/// with their byte offsets in `body`.
fn split_items(body: &str) -> Vec<(&str, usize)> {
    let mut out = Vec::new();
    let (mut start, mut quoted, mut escaped) = (0, false, false);
    for (i, c) in body.char_indices() {
        match c {
            _ if escaped => escaped = false,
            '\\' if quoted => escaped = true,
            '"' => quoted = !quoted,
            ';' | '\n' if !quoted => {
                out.push((&body[start..i], start));
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push((&body[start..], start));
    out
}

/// What our own comments carry.
#[derive(Default)]
struct Extras {
    symbols: BTreeMap<String, f64>,
    frame_names: BTreeMap<usize, String>,
    link_names: BTreeMap<usize, String>,
    notes: Vec<String>,
    robot_name: Option<String>,
    /// `(* robodyn name: ... *)`, which wins over SYMORO's `Robotname` comment.
    robodyn_name: Option<String>,
    assembly: BTreeMap<usize, (f64, usize)>,
    /// `(* robodyn limits KIND: j = value; ... *)`: (frame, kind) -> (value, position).
    limits: BTreeMap<(usize, &'static str), (f64, usize)>,
}

/// The kinds of `robodyn limits` comments, as `JointLimits` fields (`qdd` before `qd`: the
/// comment's head is matched by prefix).
const LIMIT_KINDS: [&str; 5] = ["q_min", "q_max", "qdd", "qd", "tau"];

/// Parse SYMORO's `Robotname = '...'` comment and the `robodyn ...:` blocks of our own comments.
fn parse_robodyn_comment(
    ctx: &Ctx,
    text: &str,
    at: usize,
    ex: &mut Extras,
    map: &mut SourceMap,
) -> Result<()> {
    let t = text.trim();
    if let Some(rest) = t.strip_prefix("Robotname") {
        if let Some(v) = rest.trim_start().strip_prefix('=') {
            ex.robot_name = Some(v.trim().trim_matches(['\'', '"']).to_string());
        }
        return Ok(());
    }
    let Some(rest) = t.strip_prefix("robodyn ") else {
        return Ok(());
    };
    let body_at = at + (text.len() - text.trim_start().len()) + "robodyn ".len();
    let (head, body) = match rest.split_once(':') {
        Some(x) => x,
        None => return Ok(()),
    };
    let body_at = body_at + head.len() + 1;
    let h = head.trim();
    let kind = [
        "values",
        "frame names",
        "link names",
        "note",
        "assembly",
        "limits",
        "name",
    ]
    .into_iter()
    .find(|k| h.starts_with(k));
    let limit_kind = match kind {
        Some("limits") => {
            let which = h["limits".len()..].trim();
            match LIMIT_KINDS.into_iter().find(|k| *k == which) {
                Some(k) => Some(k),
                None => {
                    return Err(ctx.err(
                        at,
                        format!(
                            "robodyn limits: `{which}` is not one of {}",
                            LIMIT_KINDS.join(", ")
                        ),
                    ))
                }
            }
        }
        _ => None,
    };
    match kind {
        Some("note") => ex.notes.push(quoted(ctx, body.trim(), body_at, "note")?),
        Some("name") => ex.robodyn_name = Some(quoted(ctx, body.trim(), body_at, "name")?),
        Some(kind) => {
            for (item, off) in split_items(body) {
                let item_at = body_at + off;
                if item.trim().is_empty() {
                    continue;
                }
                let Some(eq) = item.find('=') else {
                    return Err(ctx.err(
                        item_at,
                        format!(
                            "robodyn {kind}: expected `NAME = VALUE`, found `{}`",
                            item.trim()
                        ),
                    ));
                };
                let raw = &item[eq + 1..];
                let entry = Entry {
                    key: item[..eq].trim(),
                    value: raw.trim(),
                    at: item_at,
                    value_at: item_at + eq + 1 + (raw.len() - raw.trim_start().len()),
                };
                robodyn_entry(ctx, (kind, limit_kind), entry, ex, map)?;
            }
        }
        None => {}
    }
    Ok(())
}

/// The quoted string `v` of a `robodyn` comment (a note, a name), unquoted.
fn quoted(ctx: &Ctx, v: &str, v_at: usize, what: &str) -> Result<String> {
    uncomment_text(v).ok_or_else(|| {
        ctx.err(
            v_at,
            format!("robodyn {what}: `{v}` is not a well-formed quoted string"),
        )
    })
}

/// One `KEY = VALUE` entry of a `robodyn` comment, with the byte offsets of the entry and of its
/// value in the file.
struct Entry<'a> {
    key: &'a str,
    value: &'a str,
    at: usize,
    value_at: usize,
}

/// One entry of a `robodyn KIND:` comment (`limit_kind` for `robodyn limits KIND`) into `ex`.
fn robodyn_entry(
    ctx: &Ctx,
    (kind, limit_kind): (&str, Option<&'static str>),
    entry: Entry,
    ex: &mut Extras,
    map: &mut SourceMap,
) -> Result<()> {
    let Entry {
        key: k,
        value: v,
        at: item_at,
        value_at: v_at,
    } = entry;
    if let Some(lk) = limit_kind {
        let j: usize = k.parse().map_err(|_| {
            ctx.err(
                item_at,
                format!("robodyn limits {lk}: `{k}` is not a frame number"),
            )
        })?;
        let x = ctx
            .expr(&format!("{lk} limit of q{k}"), v, v_at)?
            .eval(&|_| None)
            .map_err(|e| ctx.err(v_at, format!("{lk} limit of q{k}: {e}")))?;
        if !x.is_finite() || (lk != "q_min" && lk != "q_max" && x <= 0.0) {
            return Err(ctx.err(
                v_at,
                format!("{lk} limit of q{k}: {x} is not a finite positive limit"),
            ));
        }
        ex.limits.insert((j, lk), (x, item_at));
    } else if kind == "assembly" {
        let j: usize = k.parse().map_err(|_| {
            ctx.err(
                item_at,
                format!("robodyn assembly: `{k}` is not a joint number"),
            )
        })?;
        let x = ctx
            .expr(&format!("assembly value of q{k}"), v, v_at)?
            .eval(&|_| None)
            .map_err(|e| ctx.err(v_at, format!("assembly value of q{k}: {e}")))?;
        ex.assembly.insert(j, (x, item_at));
    } else if kind == "values" {
        if !is_symbol_name(k) {
            return Err(ctx.err(
                item_at,
                format!("robodyn values: `{k}` is not a symbol name"),
            ));
        }
        let e = ctx.expr(&format!("value of {k}"), v, v_at)?;
        let x = e.eval(&|_| None).map_err(|e| {
            ctx.err(
                v_at,
                format!("value of {k}: {e} (values must be constants)"),
            )
        })?;
        map.set_symbol(k, ctx.line(item_at));
        ex.symbols.insert(k.to_string(), x);
    } else {
        let j: usize = k.parse().map_err(|_| {
            ctx.err(
                item_at,
                format!("robodyn {kind}: `{k}` is not a frame/link number"),
            )
        })?;
        let name = quoted(ctx, v, v_at, kind)?;
        let dst = if kind == "frame names" {
            &mut ex.frame_names
        } else {
            &mut ex.link_names
        };
        dst.insert(j, name);
    }
    Ok(())
}

/// The statements by lowercase key (`Robotname` as `name`): known keys, each once, lists where
/// lists are expected.
fn index_keys<'s>(
    ctx: &Ctx,
    statements: &'s [Statement],
) -> Result<BTreeMap<String, &'s Statement>> {
    let mut by_key: BTreeMap<String, &Statement> = BTreeMap::new();
    for st in statements {
        let kind = key_kind(&st.key).ok_or_else(|| {
            ctx.err_line(
                st.at,
                format!(
                    "unknown key `{}` (expected NL NJ NF Type is_mobile is_floating, ant sigma b \
                     d r gamma alpha mu theta, XX XY XZ YY YZ ZZ MX MY MZ M IA FV FS FX FY FZ CX \
                     CY CZ, QP QDP GAM eta k, W0 WP0 V0 VP0 G, Z or Robotname)",
                    st.key
                ),
            )
        })?;
        let list_expected = !matches!(
            kind,
            KeyKind::Count | KeyKind::Type | KeyKind::Flag | KeyKind::Name
        );
        if list_expected != st.is_list {
            return Err(ctx.err_line(
                st.at,
                if list_expected {
                    format!("{}: a list `{{...}}` is expected", st.key)
                } else {
                    format!("{}: a single value is expected, not a list", st.key)
                },
            ));
        }
        let norm = st.key.to_ascii_lowercase();
        let norm = if norm == "robotname" {
            "name".to_string()
        } else {
            norm
        };
        if let Some(prev) = by_key.insert(norm, st) {
            return Err(ctx.err_line(
                st.at,
                format!(
                    "{} is given twice (first on line {})",
                    st.key,
                    ctx.line(prev.at)
                ),
            ));
        }
    }
    Ok(by_key)
}

/// The statements of a file with the checks every value goes through.
struct Keys<'a, 's> {
    ctx: &'a Ctx<'a>,
    by_key: BTreeMap<String, &'s Statement>,
}

impl<'s> Keys<'_, 's> {
    /// A whole number, with the offset of its key.
    fn int(&self, k: &str) -> Result<Option<(i64, usize)>> {
        let Some(st) = self.by_key.get(k) else {
            return Ok(None);
        };
        let (v, at) = &st.entries[0];
        let x: i64 = v.parse().map_err(|_| {
            self.ctx
                .err(*at, format!("{}: `{v}` is not a whole number", st.key))
        })?;
        Ok(Some((x, st.at)))
    }

    /// A flag: 0/1 or the Python booleans OpenSYMORO writes (`True`, `False`, `true`, `false`).
    fn flag(&self, k: &str) -> Result<Option<(bool, usize)>> {
        let Some(st) = self.by_key.get(k) else {
            return Ok(None);
        };
        let (v, at) = &st.entries[0];
        let b = match v.as_str() {
            "1" | "True" | "true" => true,
            "0" | "False" | "false" => false,
            _ => {
                return Err(self.ctx.err(
                    *at,
                    format!("{} = {v}: expected 0 or 1 (or True, False)", st.key),
                ))
            }
        };
        Ok(Some((b, st.at)))
    }

    /// A list that must have `n` entries (`what` names n: `NF`, `NL`, `NJ` or a number).
    fn list(&self, k: &str, n: usize, what: &str) -> Result<Option<&'s Statement>> {
        let Some(st) = self.by_key.get(k).copied() else {
            return Ok(None);
        };
        if st.entries.len() != n {
            return Err(self.ctx.err_line(
                st.at,
                if what.parse::<usize>().is_ok() {
                    format!("{} has {} entries, {n} expected", st.key, st.entries.len())
                } else {
                    format!(
                        "{} has {} entries, {what} = {n} expected",
                        st.key,
                        st.entries.len()
                    )
                },
            ));
        }
        Ok(Some(st))
    }

    /// The entries of a list as whole numbers, each one of `allowed` when it is not empty.
    fn ints(&self, st: &Statement, allowed: &[i64]) -> Result<Vec<i64>> {
        st.entries
            .iter()
            .map(|(v, at)| {
                let x: i64 = v.trim().parse().map_err(|_| {
                    self.ctx
                        .err(*at, format!("{}: `{v}` is not a whole number", st.key))
                })?;
                if !allowed.is_empty() && !allowed.contains(&x) {
                    return Err(self
                        .ctx
                        .err(*at, format!("{}: {x} is not one of {allowed:?}", st.key)));
                }
                Ok(x)
            })
            .collect()
    }

    /// NL, NJ and NF = 2 NJ - NL, checked (NF as written, overflow, the lists' lengths) before
    /// anything is sized from them.
    fn counts(&self, statements: &[Statement]) -> Result<(usize, usize, usize)> {
        let ctx = self.ctx;
        let (nl, nl_at) = self
            .int("nl")?
            .ok_or_else(|| ctx.err_line(0, "the key NL (number of links) is missing"))?;
        let (nj, nj_at) = self.int("nj")?.unwrap_or((nl, nl_at));
        if nl < 1 {
            return Err(ctx.err_line(nl_at, format!("NL = {nl}: a robot has at least one link")));
        }
        if nj < nl {
            return Err(ctx.err_line(nj_at, format!("NJ = {nj} is smaller than NL = {nl}")));
        }
        let nf = nj
            .checked_mul(2)
            .and_then(|x| x.checked_sub(nl))
            .ok_or_else(|| ctx.err_line(nj_at, format!("NJ = {nj} is too large")))?;
        if let Some((f, at)) = self.int("nf")? {
            if f != nf {
                return Err(ctx.err_line(
                    at,
                    format!("NF = {f}, but NF must equal 2 NJ - NL = {nf} (NL = {nl}, NJ = {nj})"),
                ));
            }
        }
        let longest = statements
            .iter()
            .filter(|s| s.is_list)
            .map(|s| s.entries.len())
            .max()
            .unwrap_or(0);
        let limit = longest.max(FRAMES_WITHOUT_LISTS) as i64;
        if nf > limit {
            return Err(ctx.err_line(
                nj_at,
                format!(
                    "NL = {nl}, NJ = {nj} make NF = {nf} frames, but no list of the file has more \
                     than {longest} entries: a file without lists may declare at most \
                     {FRAMES_WITHOUT_LISTS} frames"
                ),
            ));
        }
        // nf <= limit, which the file's size or a small constant bounds
        Ok((nl as usize, nj as usize, nf as usize))
    }
}

/// Parse a `.par` file. `file` names the source in error messages; warnings go to the map.
pub fn parse_description(text: &str, file: Option<&str>) -> Result<(RobotDescription, SourceMap)> {
    let ctx = Ctx {
        text,
        file,
        lines: LineIndex::new(text),
    };
    let (stripped, comments) = strip_comments(&ctx)?;
    let statements = split_statements(&ctx, &stripped)?;
    let mut map = SourceMap::new(file);
    let keys = Keys {
        ctx: &ctx,
        by_key: index_keys(&ctx, &statements)?,
    };
    let (nl, nj, nf) = keys.counts(&statements)?;
    if let Some((t, at)) = keys.int("type")? {
        if !(0..=2).contains(&t) {
            return Err(ctx.err_line(
                at,
                format!("Type = {t} (0 simple chain, 1 tree, 2 closed loops)"),
            ));
        }
    }
    let mut desc = RobotDescription::new("robot", nl, nj);
    if let Some((m, _)) = keys.flag("is_mobile")? {
        desc.mobile_base = m;
    }
    if let Some((true, _)) = keys.flag("is_floating")? {
        // link 0's parameters come with the link lists (NL + 1 entries)
        desc.floating_base = Some(LinkDesc::zero("base"));
    }
    let mut ex = Extras::default();
    for (c, at) in &comments {
        parse_robodyn_comment(&ctx, c, *at, &mut ex, &mut map)?;
    }
    let statement_name = keys
        .by_key
        .get("name")
        .map(|st| st.entries[0].0.trim_matches(['\'', '"']).to_string());
    desc.name = ex
        .robodyn_name
        .take()
        .or(statement_name)
        .or(ex.robot_name.take())
        .unwrap_or_else(|| "robot".into());
    desc.symbols = std::mem::take(&mut ex.symbols);
    desc.notes = std::mem::take(&mut ex.notes);
    frame_lists(&keys, &mut desc, &mut map)?;
    for (j, n) in std::mem::take(&mut ex.frame_names) {
        if (1..=nf).contains(&j) {
            desc.frames[j - 1].name = n;
        }
    }
    link_lists(&keys, &mut desc, &mut map)?;
    for (j, n) in std::mem::take(&mut ex.link_names) {
        if (1..=nl).contains(&j) {
            desc.links[j - 1].name = n;
        }
    }
    for (&(j, kind), &(x, at)) in &ex.limits {
        if !(1..=nf).contains(&j) {
            return Err(ctx.err(
                at,
                format!("robodyn limits {kind}: frame {j} is not a frame 1..{nf}"),
            ));
        }
        let l = desc.limits.entry(j).or_default();
        match kind {
            "q_min" => l.q_min = Some(x),
            "q_max" => l.q_max = Some(x),
            "qd" => l.qd = Some(x),
            "qdd" => l.qdd = Some(x),
            _ => l.tau = Some(x),
        }
    }
    for (&j, l) in &desc.limits {
        if let (Some(a), Some(b)) = (l.q_min, l.q_max) {
            if a > b {
                let at = ex.limits[&(j, "q_min")].1;
                return Err(ctx.err(
                    at,
                    format!("robodyn limits: q{j} in [{a}, {b}] is not an interval [min, max]"),
                ));
            }
        }
    }
    if !ex.assembly.is_empty() {
        let mut q = vec![0.0; nl];
        for (&j, &(x, at)) in &ex.assembly {
            if !(1..=nl).contains(&j) {
                return Err(ctx.err(
                    at,
                    format!("robodyn assembly: joint {j} is not a tree joint 1..{nl}"),
                ));
            }
            q[j - 1] = x;
        }
        map.set_base(
            "assembly",
            ctx.line(ex.assembly.values().next().expect("one").1),
        );
        desc.assembly = Some(q);
    }
    other_lists(&keys, &mut desc, &mut map)?;
    validate_structure(&desc).map_err(|e| map.locate(e))?;
    Ok((desc, map))
}

/// The NF-entry lists: structure, joint types, actuation, geometry (joint variables removed).
fn frame_lists(keys: &Keys, desc: &mut RobotDescription, map: &mut SourceMap) -> Result<()> {
    let ctx = keys.ctx;
    let (nl, nj, nf) = (desc.nl, desc.nj, desc.nf());
    if let Some(st) = keys.list("ant", nf, "NF")? {
        for (j, a) in keys.ints(st, &[])?.into_iter().enumerate() {
            if a < 0 {
                return Err(ctx.err(
                    st.entries[j].1,
                    format!("ant: a({}) = {a} is negative", j + 1),
                ));
            }
            desc.frames[j].ant = a as usize;
            let line = ctx.line(st.entries[j].1);
            map.set_frame(j + 1, Some("ant"), line);
            map.set_frame(j + 1, None, line);
        }
    }
    if let Some(st) = keys.list("sigma", nf, "NF")? {
        for (j, s) in keys.ints(st, &[0, 1, 2])?.into_iter().enumerate() {
            desc.frames[j].joint = JointType::from_sigma(s).expect("checked");
            map.set_frame(j + 1, Some("sigma"), ctx.line(st.entries[j].1));
        }
    }
    match keys.list("mu", nf, "NF")? {
        Some(st) => {
            for (j, m) in keys.ints(st, &[0, 1])?.into_iter().enumerate() {
                desc.frames[j].actuated = m == 1;
                map.set_frame(j + 1, Some("mu"), ctx.line(st.entries[j].1));
            }
        }
        None => {
            for (j, f) in desc.frames.iter_mut().enumerate() {
                f.actuated = j < nl && f.joint.is_movable();
            }
        }
    }
    for (k, pname) in GEOMETRIC_PARAMETERS.iter().enumerate() {
        let Some(st) = keys.list(pname, nf, "NF")? else {
            continue;
        };
        for j in 1..=nf {
            let (v, at) = &st.entries[j - 1];
            let mut e = ctx.expr(&format!("frame {j}, {}", st.key), v, *at)?;
            map.set_frame(j, Some(pname), ctx.line(*at));
            let joint = desc.frames[j - 1].joint;
            let var_slot = (*pname == "theta" && joint == JointType::Revolute)
                || (*pname == "r" && joint == JointType::Prismatic);
            if var_slot && j <= nj {
                let (offset, warning) =
                    remove_joint_variable(ctx, st, j, joint, e, &desc.symbols, *at)?;
                if let Some(w) = warning {
                    map.warn(w);
                }
                e = offset;
            }
            *desc.frames[j - 1].geometric_mut()[k] = e;
        }
    }
    Ok(())
}

/// The NL-entry lists: inertial and drive parameters, external wrenches.
fn link_lists(keys: &Keys, desc: &mut RobotDescription, map: &mut SourceMap) -> Result<()> {
    let ctx = keys.ctx;
    let nl = desc.nl;
    for (k, pname) in STANDARD_PARAMETERS
        .iter()
        .chain(WRENCH_COMPONENTS.iter())
        .enumerate()
    {
        // with a mobile base, OpenSYMORO lists link 0 (the base) first: NL + 1 entries
        let key = pname.to_ascii_lowercase();
        let with_base = desc.mobile_base || desc.floating_base.is_some();
        let skip = match keys.by_key.get(key.as_str()) {
            Some(st) if with_base && st.entries.len() == nl + 1 => 1,
            _ => 0,
        };
        let Some(st) = keys.list(&key, nl + skip, "NL")? else {
            continue;
        };
        if let (1, Some(base)) = (skip, desc.floating_base.as_mut()) {
            // a floating base: link 0's own parameters (SYMORO's is_floating)
            let (v, at) = &st.entries[0];
            let e = ctx.expr(&format!("link 0, {}", st.key), v, *at)?;
            map.set_link(0, Some(pname), ctx.line(*at));
            if k < 13 {
                base.params[k] = e;
            } else {
                base.wrench[k - 13] = e;
            }
        } else if skip == 1 && !st.entries[0].0.trim().eq("0") {
            desc.notes.push(format!(
                "{}: the entry of link 0 (the mobile base) is not used: the base motion is \
                 prescribed by W0 WP0 V0 VP0",
                st.key
            ));
        }
        for j in 1..=nl {
            let (v, at) = &st.entries[j - 1 + skip];
            let e = ctx.expr(&format!("link {j}, {}", st.key), v, *at)?;
            map.set_link(j, Some(pname), ctx.line(*at));
            if k < 13 {
                desc.links[j - 1].params[k] = e;
            } else {
                desc.links[j - 1].wrench[k - 13] = e;
            }
        }
    }
    Ok(())
}

/// The NJ-entry lists (checked, flexibility noted), the base matrix Z (noted when it is not the
/// identity), gravity and the base velocities and accelerations.
fn other_lists(keys: &Keys, desc: &mut RobotDescription, map: &mut SourceMap) -> Result<()> {
    let ctx = keys.ctx;
    for k in ["qp", "qdp", "gam", "eta", "k"] {
        if let Some(st) = keys.list(k, desc.nj, "NJ")? {
            for (v, at) in &st.entries {
                let e = ctx.expr(&st.key, v, *at)?;
                if k == "eta" && !e.is_zero() {
                    desc.notes.push(
                        "the file declares flexible joints (eta, k): robodyn ignores joint \
                         flexibility"
                            .into(),
                    );
                    break;
                }
            }
        }
    }
    if let Some(st) = keys.list("z", 16, "16")? {
        let mut z = [0.0; 16];
        for (i, (v, at)) in st.entries.iter().enumerate() {
            let e = ctx.expr("Z", v, *at)?;
            z[i] = e
                .eval(&|s| desc.symbols.get(s).copied())
                .unwrap_or(f64::NAN);
        }
        let identity = (0..16).all(|i| z[i] == if i % 5 == 0 { 1.0 } else { 0.0 });
        if !identity {
            desc.notes.push(format!(
                "the file's base matrix Z = {{{}}} is not the identity: robodyn's frame 0 is the \
                 robot's base frame; Z is not applied",
                st.entries
                    .iter()
                    .map(|e| e.0.as_str())
                    .collect::<Vec<_>>()
                    .join(",")
            ));
        }
    }
    for (k, name) in [
        ("g", "G"),
        ("w0", "W0"),
        ("wp0", "WP0"),
        ("v0", "V0"),
        ("vp0", "VP0"),
    ] {
        if let Some(st) = keys.list(k, 3, "3")? {
            map.set_base(name, ctx.line(st.at));
            let mut v: [Expr; 3] = std::array::from_fn(|_| Expr::zero());
            for (i, (s, at)) in st.entries.iter().enumerate() {
                v[i] = ctx.expr(&st.key, s, *at)?;
            }
            match k {
                "g" => desc.gravity = v,
                "w0" => desc.w0 = v,
                "wp0" => desc.wp0 = v,
                "v0" => desc.v0 = v,
                _ => desc.vp0 = v,
            }
        }
    }
    Ok(())
}

/// Split a `theta` (revolute) or `r` (prismatic) entry into the joint variable and the constant
/// offset, as SYMORO reads it (the entry is the joint variable):
/// - the variable is the entry's symbol without a value; among several, the one named like a
///   joint variable (`th3`, `q3`, `t3`, `theta3`; `r3`, `q3`); it must enter with coefficient 1
///   (checked by evaluating at three points with the other symbols at arbitrary values), and what
///   remains is the offset;
/// - an entry without such a symbol (a number, a constant expression) is the value SYMORO gives
///   the variable, not an offset: the offset is 0 and, when the value is not 0, a warning says
///   how SYMORO's models relate to robodyn's.
fn remove_joint_variable(
    ctx: &Ctx,
    st: &Statement,
    j: usize,
    joint: JointType,
    e: Expr,
    values: &BTreeMap<String, f64>,
    at: usize,
) -> Result<(Expr, Option<Warning>)> {
    let unknown: Vec<String> = e
        .symbols()
        .into_iter()
        .filter(|s| !values.contains_key(s))
        .collect();
    let named: Vec<&String> = unknown
        .iter()
        .filter(|s| is_variable_name(s, joint))
        .collect();
    let var = match (unknown.as_slice(), named.as_slice()) {
        ([], _) => {
            let v = e.eval(&|s| values.get(s).copied()).ok();
            let param = if joint == JointType::Revolute {
                "theta"
            } else {
                "r"
            };
            let prefix = if joint == JointType::Revolute {
                "th"
            } else {
                "r"
            };
            let warning = (v != Some(0.0)).then(|| {
                Warning::new(
                    Item::Frame(j, Some(param.into())),
                    format!(
                        "{} = {e} on a {} joint: SYMORO reads this entry as the joint variable \
                         itself, so the file describes the robot at q{j} = {e}; robodyn reads it \
                         the same way (the joint's {param} is q{j}, with no constant offset). \
                         Write `{prefix}{j} + {e}` if {e} is meant as an offset",
                        st.key,
                        if joint == JointType::Revolute {
                            "revolute"
                        } else {
                            "prismatic"
                        },
                    ),
                )
            });
            return Ok((Expr::zero(), warning));
        }
        ([v], _) => v.clone(),
        (_, [v]) => (*v).clone(),
        (many, _) => {
            return Err(ctx.err(
                at,
                format!(
                    "{} of frame {j}: several candidates for the joint variable ({}): name it \
                     th{j} (or q{j}) and give the others a value",
                    st.key,
                    many.join(", ")
                ),
            ))
        }
    };
    let offset = e.substitute(&|s| (s == var).then(Expr::zero));
    // Arbitrary values for the other symbols: the check must hold for any values.
    let others: BTreeSet<String> = e.symbols().into_iter().filter(|s| *s != var).collect();
    let env_at = |x: f64| {
        let others = &others;
        let var = &var;
        move |s: &str| -> Option<f64> {
            if s == var {
                Some(x)
            } else {
                let i = others.iter().position(|o| o == s)?;
                Some(values.get(s).copied().unwrap_or(0.3 + 0.17 * i as f64))
            }
        }
    };
    for x in [0.0, 0.7, -1.9] {
        let a = e.eval(&env_at(x));
        let b = offset.eval(&env_at(x));
        let ok = match (a, b) {
            (Ok(a), Ok(b)) => (a - b - x).abs() <= 1e-9 * (1.0 + a.abs() + b.abs()),
            _ => false,
        };
        if !ok {
            return Err(ctx.err(
                at,
                format!(
                    "{} of frame {j}: the joint variable `{var}` must enter with coefficient 1 \
                     (e.g. `{var}` or `{var} + pi/2`), found `{}`",
                    st.key, e
                ),
            ));
        }
    }
    Ok((offset, None))
}

fn structure_type(desc: &RobotDescription) -> u8 {
    if desc.nj > desc.nl {
        2
    } else if desc.frames.iter().enumerate().all(|(i, f)| f.ant == i) {
        0
    } else {
        1
    }
}

/// The robot name as SYMORO's `Robotname` comment can hold it (robodyn's own name comment
/// keeps the exact name when this changes it).
fn symoro_name(s: &str) -> String {
    s.replace(['\n', '\r', '\'', '*'], "_")
}

/// Write a description as a SYMORO `.par` file (plus our values/names in comments).
pub fn write_description(desc: &RobotDescription) -> String {
    let mut s = String::new();
    write_header(&mut s, desc);
    write_geometry(&mut s, desc);
    write_dynamics(&mut s, desc);
    write_extensions(&mut s, desc);
    s.push_str("\n(* End of definition *)\n");
    s
}

/// A SYMORO list: `{a,b,c}`.
fn par_list(items: Vec<String>) -> String {
    format!("{{{}}}", items.join(","))
}

/// The robot's name (and robodyn's own name and notes as comments) and its counts.
fn write_header(s: &mut String, desc: &RobotDescription) {
    let nf = desc.nf();
    let name = symoro_name(&desc.name);
    s.push_str(&format!("(* Robotname = '{name}' *)\n"));
    if name != desc.name || name.trim() != name || name.is_empty() {
        s.push_str(&format!(
            "(* robodyn name: {} *)\n",
            comment_text(&desc.name)
        ));
    }
    for n in &desc.notes {
        s.push_str(&format!("(* robodyn note: {} *)\n", comment_text(n)));
    }
    s.push_str(&format!(
        "NL = {}\nNJ = {}\nNF = {nf}\nType = {}\nis_mobile = {}\n",
        desc.nl,
        desc.nj,
        structure_type(desc),
        u8::from(desc.mobile_base)
    ));
    if desc.floating_base.is_some() {
        s.push_str("is_floating = 1\n");
    }
}

/// The geometric parameters, the joint variables named after no symbol of the description.
fn write_geometry(s: &mut String, desc: &RobotDescription) {
    let nf = desc.nf();
    s.push_str("\n(* Geometric parameters *)\n");
    s.push_str(&format!(
        "ant = {}\n",
        par_list(desc.frames.iter().map(|f| f.ant.to_string()).collect())
    ));
    s.push_str(&format!(
        "sigma = {}\n",
        par_list(
            desc.frames
                .iter()
                .map(|f| f.joint.sigma().to_string())
                .collect()
        )
    ));
    // joint-variable names that collide with no symbol of the description
    let used: BTreeSet<String> = desc
        .frames
        .iter()
        .flat_map(|f| f.geometric().into_iter().flat_map(|e| e.symbols()))
        .chain(desc.symbols.keys().cloned())
        .collect();
    let prefix = |joint: JointType| -> &'static str {
        let cands: &[&'static str] = if joint == JointType::Prismatic {
            &["r", "q"]
        } else {
            &["th", "q", "t", "theta"]
        };
        cands
            .iter()
            .copied()
            .find(|p| (1..=nf).all(|j| !used.contains(&format!("{p}{j}"))))
            .unwrap_or(cands[0])
    };
    let (rev, pri) = (prefix(JointType::Revolute), prefix(JointType::Prismatic));
    for p in ["b", "d", "r", "gamma", "alpha", "mu", "theta"].iter() {
        let items: Vec<String> = desc
            .frames
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let j = i + 1;
                let var = |pre: &str, e: &Expr| -> String {
                    if e.is_zero() {
                        format!("{pre}{j}")
                    } else {
                        (Expr::symbol(format!("{pre}{j}")) + e.clone())
                            .decimal()
                            .to_string()
                    }
                };
                match *p {
                    "b" => f.b.decimal().to_string(),
                    "d" => f.d.decimal().to_string(),
                    "gamma" => f.gamma.decimal().to_string(),
                    "alpha" => f.alpha.decimal().to_string(),
                    "mu" => u8::from(f.actuated).to_string(),
                    "r" if f.joint == JointType::Prismatic && j <= desc.nj => var(pri, &f.r),
                    "r" => f.r.decimal().to_string(),
                    _ if f.joint == JointType::Revolute && j <= desc.nj => var(rev, &f.theta),
                    _ => f.theta.decimal().to_string(),
                }
            })
            .collect();
        s.push_str(&format!("{p} = {}\n", par_list(items)));
    }
}

/// The dynamic parameters, external forces, joint and base motion, and gravity.
fn write_dynamics(s: &mut String, desc: &RobotDescription) {
    s.push_str("\n(* Dynamic parameters and external forces *)\n");
    let order = [
        "XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M", "IA", "FV", "FS", "FX", "FY",
        "FZ", "CX", "CY", "CZ",
    ];
    for name in order {
        // a mobile base is link 0 of the lists (OpenSYMORO's convention); robodyn has no
        // parameters for it (its motion is prescribed), so it is written as 0
        let base = desc.mobile_base.then(|| "0".to_string());
        let items: Vec<String> = base
            .into_iter()
            .chain(desc.floating_base.iter().chain(&desc.links).map(|l| {
                match STANDARD_PARAMETERS.iter().position(|p| *p == name) {
                    Some(k) => l.params[k].decimal().to_string(),
                    None => {
                        let k = WRENCH_COMPONENTS
                            .iter()
                            .position(|p| *p == name)
                            .expect("known");
                        l.wrench[k].decimal().to_string()
                    }
                }
            }))
            .collect();
        s.push_str(&format!("{name} = {}\n", par_list(items)));
    }
    s.push_str("\n(* Joint velocities and accelerations *)\n");
    for name in ["QP", "QDP", "GAM"] {
        let items: Vec<String> = (1..=desc.nj).map(|j| format!("{name}{j}")).collect();
        s.push_str(&format!("{name} = {}\n", par_list(items)));
    }
    s.push_str("\n(* Speed and acceleration of the base *)\n");
    for (name, v) in [
        ("W0", &desc.w0),
        ("WP0", &desc.wp0),
        ("V0", &desc.v0),
        ("VP0", &desc.vp0),
    ] {
        s.push_str(&format!(
            "{name} = {}\n",
            par_list(v.iter().map(|e| e.decimal().to_string()).collect())
        ));
    }
    s.push_str("\n(* Matrix Z *)\nZ = {1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1}\n");
    s.push_str("\n(* Acceleration of gravity *)\n");
    s.push_str(&format!(
        "G = {}\n",
        par_list(
            desc.gravity
                .iter()
                .map(|e| e.decimal().to_string())
                .collect()
        )
    ));
}

/// What SYMORO has no field for, as robodyn comments: frame and link names, limits, the
/// assembly, the symbols' values.
fn write_extensions(s: &mut String, desc: &RobotDescription) {
    let default_frame = |j: usize, n: &str| n == format!("j{j}");
    if desc
        .frames
        .iter()
        .enumerate()
        .any(|(i, f)| !default_frame(i + 1, &f.name))
    {
        let items: Vec<String> = desc
            .frames
            .iter()
            .enumerate()
            .map(|(i, f)| format!("{} = {}", i + 1, comment_text(&f.name)))
            .collect();
        s.push_str(&format!(
            "\n(* robodyn frame names: {} *)\n",
            items.join("; ")
        ));
    }
    if desc
        .links
        .iter()
        .enumerate()
        .any(|(i, l)| l.name != format!("link{}", i + 1))
    {
        let items: Vec<String> = desc
            .links
            .iter()
            .enumerate()
            .map(|(i, l)| format!("{} = {}", i + 1, comment_text(&l.name)))
            .collect();
        s.push_str(&format!("(* robodyn link names: {} *)\n", items.join("; ")));
    }
    for kind in LIMIT_KINDS {
        let items: Vec<String> = desc
            .limits
            .iter()
            .filter_map(|(j, l)| {
                let x = match kind {
                    "q_min" => l.q_min,
                    "q_max" => l.q_max,
                    "qd" => l.qd,
                    "qdd" => l.qdd,
                    _ => l.tau,
                }?;
                Some(format!("{j} = {x:?}"))
            })
            .collect();
        if !items.is_empty() {
            s.push_str(&format!(
                "(* robodyn limits {kind}: {} *)\n",
                items.join("; ")
            ));
        }
    }
    if let Some(q) = &desc.assembly {
        let items: Vec<String> = q
            .iter()
            .enumerate()
            .map(|(i, x)| format!("{} = {x:?}", i + 1))
            .collect();
        s.push_str(&format!(
            "\n(* robodyn assembly (joint values where the loops close): {} *)\n",
            items.join("; ")
        ));
    }
    if !desc.symbols.is_empty() {
        let items: Vec<String> = desc
            .symbols
            .iter()
            .map(|(k, v)| format!("{k} = {v:?}"))
            .collect();
        s.push_str(&format!(
            "\n(* robodyn values (numeric values of the symbols, ignored by SYMORO):\n   {} *)\n",
            items.join(";\n   ")
        ));
    }
}
