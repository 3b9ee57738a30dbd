//! SYMORO's `.par` robot files, read and written.
//!
//! The dialect accepted (see `docs/robot-format.md`):
//! - `(* comments *)`, possibly spanning lines;
//! - `NL NJ NF Type is_mobile` scalars (`NF` must equal 2 NJ - NL);
//! - lists `{a, b, ...}` of NF entries: `ant sigma b d r gamma alpha mu theta` (SYMORO+'s
//!   capitalised `Ant Mu Sigma B Alpha Theta R` too; keys are case-insensitive);
//! - lists of NL entries: `XX XY XZ YY YZ ZZ MX MY MZ M IA FV FS FX FY FZ CX CY CZ`;
//! - lists of NJ entries `QP QDP GAM` (symbolic joint velocities etc., checked and ignored);
//! - `W0 WP0 V0 VP0 G` of 3 entries (`G` is the gravity acceleration g in frame 0), `Z` of 16;
//! - `Robotname = 'name'` or `name = ...`, also inside a comment as SYMORO writes it.
//!
//! In `theta` of a revolute joint and `r` of a prismatic joint, a name such as `th3`, `q3`, `t3`
//! (resp. `r3`, `q3`) without a numeric value is the joint variable; it must enter with
//! coefficient 1 (`th3 + pi/2`); what remains is the constant offset we store.
//!
//! SYMORO files carry no numeric values for their symbols. Our writer stores them in a comment
//! SYMORO ignores, `(* robodyn values: d2 = 0.15; d3 = 0.6 *)`, which our reader reads back (as
//! it does `(* robodyn frame names: ... *)`, `(* robodyn link names: ... *)` and
//! `(* robodyn note: ... *)`), so that `.par -> .toml -> .par` round-trips.

use crate::error::{Error, Location, Result};
use crate::io::SourceMap;
use crate::model::{
    validate_structure, JointType, RobotDescription, GEOMETRIC_PARAMETERS, STANDARD_PARAMETERS,
    WRENCH_COMPONENTS,
};
use robodyn_symbolic::Expr;
use std::collections::{BTreeMap, BTreeSet};

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
}

impl Ctx<'_> {
    fn pos(&self, offset: usize) -> (usize, usize) {
        let before = &self.text[..offset.min(self.text.len())];
        let line = before.matches('\n').count() + 1;
        let col = before.len() - before.rfind('\n').map(|p| p + 1).unwrap_or(0) + 1;
        (line, col)
    }
    fn line(&self, offset: usize) -> usize {
        self.pos(offset).0
    }
    fn err(&self, offset: usize, reason: impl Into<String>) -> Error {
        let (line, col) = self.pos(offset);
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
    Mobile,   // is_mobile
    Name,     // robotname, name
    PerFrame, // ant sigma b d r gamma alpha mu theta
    PerLink,  // XX ... CZ
    PerJoint, // QP QDP GAM
    Base,     // W0 WP0 V0 VP0 G
    ZMatrix,  // Z
}

fn key_kind(k: &str) -> Option<KeyKind> {
    Some(match k.to_ascii_lowercase().as_str() {
        "nl" | "nj" | "nf" => KeyKind::Count,
        "type" => KeyKind::Type,
        "is_mobile" | "is_floating" => KeyKind::Mobile,
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

/// What our own comments carry.
#[derive(Default)]
struct Extras {
    symbols: BTreeMap<String, f64>,
    frame_names: BTreeMap<usize, String>,
    link_names: BTreeMap<usize, String>,
    notes: Vec<String>,
    robot_name: Option<String>,
    assembly: BTreeMap<usize, f64>,
}

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
    let kind = ["values", "frame names", "link names", "note", "assembly"]
        .into_iter()
        .find(|k| h.starts_with(k));
    match kind {
        Some("note") => ex.notes.push(body.trim().to_string()),
        Some(kind) => {
            let mut off = 0;
            for item in body.split([';', '\n']) {
                let item_at = body_at + off;
                off += item.len() + 1;
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
                let k = item[..eq].trim();
                let raw = &item[eq + 1..];
                let v = raw.trim();
                let v_at = item_at + eq + 1 + (raw.len() - raw.trim_start().len());
                if kind == "assembly" {
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
                    ex.assembly.insert(j, x);
                } else if kind == "values" {
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
                    let dst = if kind == "frame names" {
                        &mut ex.frame_names
                    } else {
                        &mut ex.link_names
                    };
                    dst.insert(j, v.to_string());
                }
            }
        }
        None => {}
    }
    Ok(())
}

/// Parse a `.par` file. `file` names the source in error messages.
pub fn parse_description(text: &str, file: Option<&str>) -> Result<(RobotDescription, SourceMap)> {
    let ctx = Ctx { text, file };
    let (stripped, comments) = strip_comments(&ctx)?;
    let statements = split_statements(&ctx, &stripped)?;
    let mut map = SourceMap::default();
    map.file = file.map(str::to_string);

    // keys: known, not repeated
    let mut by_key: BTreeMap<String, &Statement> = BTreeMap::new();
    for st in &statements {
        let kind = key_kind(&st.key).ok_or_else(|| {
            ctx.err_line(
                st.at,
                format!(
                    "unknown key `{}` (expected NL NJ NF Type is_mobile, ant sigma b d r gamma \
                     alpha mu theta, XX XY XZ YY YZ ZZ MX MY MZ M IA FV FS FX FY FZ CX CY CZ, \
                     QP QDP GAM, W0 WP0 V0 VP0 G, Z or Robotname)",
                    st.key
                ),
            )
        })?;
        let list_expected = !matches!(
            kind,
            KeyKind::Count | KeyKind::Type | KeyKind::Mobile | KeyKind::Name
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
    let int_of = |k: &str| -> Result<Option<(i64, usize)>> {
        match by_key.get(k) {
            None => Ok(None),
            Some(st) => {
                let (v, at) = &st.entries[0];
                let x: i64 = v.parse().map_err(|_| {
                    ctx.err(*at, format!("{}: `{v}` is not a whole number", st.key))
                })?;
                Ok(Some((x, st.at)))
            }
        }
    };
    let (nl, nl_at) =
        int_of("nl")?.ok_or_else(|| ctx.err_line(0, "the key NL (number of links) is missing"))?;
    let (nj, nj_at) = int_of("nj")?.unwrap_or((nl, nl_at));
    if nl < 1 {
        return Err(ctx.err_line(nl_at, format!("NL = {nl}: a robot has at least one link")));
    }
    if nj < nl {
        return Err(ctx.err_line(nj_at, format!("NJ = {nj} is smaller than NL = {nl}")));
    }
    let (nl, nj) = (nl as usize, nj as usize);
    let nf = 2 * nj - nl;
    if let Some((f, at)) = int_of("nf")? {
        if f != nf as i64 {
            return Err(ctx.err_line(
                at,
                format!("NF = {f}, but NF must equal 2 NJ - NL = {nf} (NL = {nl}, NJ = {nj})"),
            ));
        }
    }
    if let Some((t, at)) = int_of("type")? {
        if !(0..=2).contains(&t) {
            return Err(ctx.err_line(
                at,
                format!("Type = {t} (0 simple chain, 1 tree, 2 closed loops)"),
            ));
        }
    }

    let mut robot_name = by_key
        .get("name")
        .map(|st| st.entries[0].0.trim_matches(['\'', '"']).to_string());
    let mut desc = RobotDescription::new("robot", nl, nj);
    if let Some((m, at)) = int_of("is_mobile")? {
        desc.mobile_base = match m {
            0 => false,
            1 => true,
            _ => return Err(ctx.err_line(at, format!("is_mobile = {m} (0 or 1)"))),
        };
    }
    if let Some((m, at)) = int_of("is_floating")? {
        if m != 0 {
            return Err(ctx.err_line(
                at,
                format!(
                    "is_floating = {m}: a floating (free) base is not supported; robodyn's base \
                     is fixed or moves as given by W0 WP0 V0 VP0 (is_mobile = 1)"
                ),
            ));
        }
    }
    let mut ex = Extras::default();
    for (c, at) in &comments {
        parse_robodyn_comment(&ctx, c, *at, &mut ex, &mut map)?;
    }
    if robot_name.is_none() {
        robot_name = ex.robot_name.take();
    }
    desc.name = robot_name.unwrap_or_else(|| "robot".into());
    desc.symbols = std::mem::take(&mut ex.symbols);
    desc.notes = std::mem::take(&mut ex.notes);

    let list = |k: &str, n: usize, what: &str| -> Result<Option<&Statement>> {
        match by_key.get(k) {
            None => Ok(None),
            Some(st) => {
                if st.entries.len() != n {
                    return Err(ctx.err_line(
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
        }
    };
    let ints = |st: &Statement, allowed: &[i64]| -> Result<Vec<i64>> {
        st.entries
            .iter()
            .map(|(v, at)| {
                let x: i64 = v.trim().parse().map_err(|_| {
                    ctx.err(*at, format!("{}: `{v}` is not a whole number", st.key))
                })?;
                if !allowed.is_empty() && !allowed.contains(&x) {
                    return Err(ctx.err(*at, format!("{}: {x} is not one of {allowed:?}", st.key)));
                }
                Ok(x)
            })
            .collect()
    };

    // frame lists
    if let Some(st) = list("ant", nf, "NF")? {
        for (j, a) in ints(st, &[])?.into_iter().enumerate() {
            if a < 0 {
                return Err(ctx.err(
                    st.entries[j].1,
                    format!("ant: a({}) = {a} is negative", j + 1),
                ));
            }
            desc.frames[j].ant = a as usize;
            map.set_frame(j + 1, Some("ant"), ctx.line(st.entries[j].1));
        }
    }
    for j in 1..=nf {
        let line = by_key.get("ant").map(|s| ctx.line(s.entries[j - 1].1));
        if let Some(l) = line {
            map.set_frame(j, None, l);
        }
    }
    if let Some(st) = list("sigma", nf, "NF")? {
        for (j, s) in ints(st, &[0, 1, 2])?.into_iter().enumerate() {
            desc.frames[j].joint = JointType::from_sigma(s).expect("checked");
            map.set_frame(j + 1, Some("sigma"), ctx.line(st.entries[j].1));
        }
    }
    match list("mu", nf, "NF")? {
        Some(st) => {
            for (j, m) in ints(st, &[0, 1])?.into_iter().enumerate() {
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
        let Some(st) = list(pname, nf, "NF")? else {
            continue;
        };
        for j in 1..=nf {
            let (v, at) = &st.entries[j - 1];
            let mut e = ctx.expr(&format!("{} of frame {j}", st.key), v, *at)?;
            map.set_frame(j, Some(pname), ctx.line(*at));
            let joint = desc.frames[j - 1].joint;
            let var_slot = (*pname == "theta" && joint == JointType::Revolute)
                || (*pname == "r" && joint == JointType::Prismatic);
            if var_slot && j <= nj {
                e = remove_joint_variable(&ctx, st, j, joint, e, &desc.symbols, *at)?;
            }
            *desc.frames[j - 1].geometric_mut()[k] = e;
        }
    }
    for (j, n) in std::mem::take(&mut ex.frame_names) {
        if (1..=nf).contains(&j) {
            desc.frames[j - 1].name = n;
        }
    }

    // link lists
    for (k, pname) in STANDARD_PARAMETERS
        .iter()
        .chain(WRENCH_COMPONENTS.iter())
        .enumerate()
    {
        // with a mobile base, OpenSYMORO lists link 0 (the base) first: NL + 1 entries
        let key = pname.to_ascii_lowercase();
        let skip = match by_key.get(key.as_str()) {
            Some(st) if desc.mobile_base && st.entries.len() == nl + 1 => 1,
            _ => 0,
        };
        let Some(st) = list(&key, nl + skip, "NL")? else {
            continue;
        };
        if skip == 1 && !st.entries[0].0.trim().eq("0") {
            desc.notes.push(format!(
                "{}: the entry of link 0 (the mobile base) is not used: the base motion is \
                 prescribed by W0 WP0 V0 VP0",
                st.key
            ));
        }
        for j in 1..=nl {
            let (v, at) = &st.entries[j - 1 + skip];
            let e = ctx.expr(&format!("{} of link {j}", st.key), v, *at)?;
            map.set_link(j, Some(pname), ctx.line(*at));
            if k < 13 {
                desc.links[j - 1].params[k] = e;
            } else {
                desc.links[j - 1].wrench[k - 13] = e;
            }
        }
    }
    if !ex.assembly.is_empty() {
        let mut q = vec![0.0; nl];
        for (&j, &x) in &ex.assembly {
            if !(1..=nl).contains(&j) {
                return Err(Error::parse(
                    file,
                    1,
                    format!("robodyn assembly: joint {j} is not a tree joint 1..{nl}"),
                ));
            }
            q[j - 1] = x;
        }
        desc.assembly = Some(q);
    }
    for (j, n) in std::mem::take(&mut ex.link_names) {
        if (1..=nl).contains(&j) {
            desc.links[j - 1].name = n;
        }
    }
    for k in ["qp", "qdp", "gam", "eta", "k"] {
        if let Some(st) = list(k, nj, "NJ")? {
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
    if let Some(st) = list("z", 16, "16")? {
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
        if let Some(st) = list(k, 3, "3")? {
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
    validate_structure(&desc).map_err(|e| map.locate(e))?;
    Ok((desc, map))
}

/// Strip the joint variable from a `theta` (revolute) or `r` (prismatic) entry: the variable must
/// enter with coefficient 1 (checked by evaluating at two points with the other symbols at
/// arbitrary values); the rest is the constant offset.
fn remove_joint_variable(
    ctx: &Ctx,
    st: &Statement,
    j: usize,
    joint: JointType,
    e: Expr,
    values: &BTreeMap<String, f64>,
    at: usize,
) -> Result<Expr> {
    let vars: Vec<String> = e
        .symbols()
        .into_iter()
        .filter(|s| !values.contains_key(s) && is_variable_name(s, joint))
        .collect();
    let var = match vars.as_slice() {
        [] => return Ok(e), // a number or constant expression: the offset alone
        [v] => v.clone(),
        many => {
            return Err(ctx.err(
                at,
                format!(
                    "{} of frame {j}: several joint variables ({})",
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
    Ok(offset)
}

/// The Type of a description: 0 simple chain, 1 tree, 2 closed loops.
fn structure_type(desc: &RobotDescription) -> u8 {
    if desc.nj > desc.nl {
        2
    } else if desc.frames.iter().enumerate().all(|(i, f)| f.ant == i) {
        0
    } else {
        1
    }
}

/// A name safe inside a comment and a `;`-separated list.
fn clean_name(s: &str) -> String {
    s.replace([';', '\n'], "_")
        .replace("(*", "( *")
        .replace("*)", "* )")
}

/// Write a description as a SYMORO `.par` file (plus our values/names in comments).
pub fn write_description(desc: &RobotDescription) -> String {
    let nf = desc.nf();
    let mut s = String::new();
    s.push_str(&format!("(* Robotname = '{}' *)\n", clean_name(&desc.name)));
    for n in &desc.notes {
        s.push_str(&format!("(* robodyn note: {} *)\n", n.replace("*)", "* )")));
    }
    s.push_str(&format!(
        "NL = {}\nNJ = {}\nNF = {nf}\nType = {}\nis_mobile = {}\n",
        desc.nl,
        desc.nj,
        structure_type(desc),
        u8::from(desc.mobile_base)
    ));
    let list = |items: Vec<String>| format!("{{{}}}", items.join(","));
    s.push_str("\n(* Geometric parameters *)\n");
    s.push_str(&format!(
        "ant = {}\n",
        list(desc.frames.iter().map(|f| f.ant.to_string()).collect())
    ));
    s.push_str(&format!(
        "sigma = {}\n",
        list(
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
                        (Expr::symbol(format!("{pre}{j}")) + e.clone()).to_string()
                    }
                };
                match *p {
                    "b" => f.b.to_string(),
                    "d" => f.d.to_string(),
                    "gamma" => f.gamma.to_string(),
                    "alpha" => f.alpha.to_string(),
                    "mu" => u8::from(f.actuated).to_string(),
                    "r" if f.joint == JointType::Prismatic && j <= desc.nj => var(pri, &f.r),
                    "r" => f.r.to_string(),
                    _ if f.joint == JointType::Revolute && j <= desc.nj => var(rev, &f.theta),
                    _ => f.theta.to_string(),
                }
            })
            .collect();
        s.push_str(&format!("{p} = {}\n", list(items)));
    }
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
            .chain(desc.links.iter().map(|l| {
                match STANDARD_PARAMETERS.iter().position(|p| *p == name) {
                    Some(k) => l.params[k].to_string(),
                    None => {
                        let k = WRENCH_COMPONENTS
                            .iter()
                            .position(|p| *p == name)
                            .expect("known");
                        l.wrench[k].to_string()
                    }
                }
            }))
            .collect();
        s.push_str(&format!("{name} = {}\n", list(items)));
    }
    s.push_str("\n(* Joint velocities and accelerations *)\n");
    for name in ["QP", "QDP", "GAM"] {
        let items: Vec<String> = (1..=desc.nj).map(|j| format!("{name}{j}")).collect();
        s.push_str(&format!("{name} = {}\n", list(items)));
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
            list(v.iter().map(|e| e.to_string()).collect())
        ));
    }
    s.push_str("\n(* Matrix Z *)\nZ = {1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1}\n");
    s.push_str("\n(* Acceleration of gravity *)\n");
    s.push_str(&format!(
        "G = {}\n",
        list(desc.gravity.iter().map(|e| e.to_string()).collect())
    ));
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
            .map(|(i, f)| format!("{} = {}", i + 1, clean_name(&f.name)))
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
            .map(|(i, l)| format!("{} = {}", i + 1, clean_name(&l.name)))
            .collect();
        s.push_str(&format!("(* robodyn link names: {} *)\n", items.join("; ")));
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
    s.push_str("\n(* End of definition *)\n");
    s
}
