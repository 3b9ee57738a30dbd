//! The native TOML robot format (documented in `docs/robot-format.md`).
//!
//! Every value may be a number or a string holding an expression over the symbols of the
//! `[symbols]` table. Errors carry the file and line of the offending entry, and the key.
//!
//! Reading is linear in the file size: positions come from a [`LineIndex`], and the counts
//! `nl`/`nj` are checked against the tables the file actually has before anything is sized
//! from them.

use crate::error::{Error, Location, Result};
use crate::io::source::LineIndex;
pub use crate::io::SourceMap;
use crate::model::{
    validate_structure, JointLimits, JointType, LinkDesc, RobotDescription, Tool, Transmission,
    GEOMETRIC_PARAMETERS, STANDARD_PARAMETERS, WRENCH_COMPONENTS,
};
use crate::Robot;
use robodyn_symbolic::{Expr, Node};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::ops::Range;
use toml::Spanned;

#[derive(Deserialize, Debug, Clone)]
#[serde(untagged)]
enum Value {
    Int(i64),
    Float(f64),
    Str(String),
}

type SV = Spanned<Value>;

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FileTop {
    name: Option<String>,
    notes: Option<Vec<String>>,
    nl: Option<Spanned<usize>>,
    nj: Option<Spanned<usize>>,
    mobile_base: Option<bool>,
    base: Option<Spanned<String>>,
    base_link: Option<Spanned<LinkTable>>,
    gravity: Option<Spanned<Vec<SV>>>,
    w0: Option<Spanned<Vec<SV>>>,
    wp0: Option<Spanned<Vec<SV>>>,
    v0: Option<Spanned<Vec<SV>>>,
    vp0: Option<Spanned<Vec<SV>>>,
    assembly: Option<Spanned<Vec<SV>>>,
    #[serde(default)]
    symbols: BTreeMap<String, Spanned<Value>>,
    #[serde(default)]
    frame: Vec<Spanned<FrameTable>>,
    #[serde(default)]
    link: Vec<Spanned<LinkTable>>,
    transmission: Option<Spanned<TransmissionTable>>,
    #[serde(default)]
    tool: Vec<Spanned<ToolTable>>,
}

/// `[[tool]]`: a named frame fixed on a frame (see `docs/robot-format.md`).
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct ToolTable {
    name: Spanned<String>,
    frame: Spanned<FrameRef>,
    xyz: Option<Spanned<Vec<SV>>>,
    rpy: Option<Spanned<Vec<SV>>>,
}

/// The frame a tool is fixed on: its number or the name of a frame or link.
#[derive(Deserialize, Debug)]
#[serde(untagged)]
enum FrameRef {
    Number(i64),
    Name(String),
}

/// `[transmission]`: m = R q over the actuated joints (see `docs/robot-format.md`).
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct TransmissionTable {
    joints: Option<Vec<usize>>,
    matrix: Vec<Vec<SV>>,
}

/// `limits = { q = [min, max], qd = .., qdd = .., tau = .. }` of a `[[frame]]`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct LimitsTable {
    q: Option<Vec<SV>>,
    qd: Option<SV>,
    qdd: Option<SV>,
    tau: Option<SV>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct FrameTable {
    j: Option<Spanned<usize>>,
    name: Option<String>,
    ant: Spanned<usize>,
    sigma: Option<Spanned<i64>>,
    #[serde(rename = "type")]
    kind: Option<Spanned<String>>,
    mu: Option<Spanned<i64>>,
    gamma: Option<SV>,
    b: Option<SV>,
    alpha: Option<SV>,
    d: Option<SV>,
    theta: Option<SV>,
    r: Option<SV>,
    limits: Option<Spanned<LimitsTable>>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
#[allow(non_snake_case)]
struct LinkTable {
    j: Option<Spanned<usize>>,
    name: Option<String>,
    XX: Option<SV>,
    XY: Option<SV>,
    XZ: Option<SV>,
    YY: Option<SV>,
    YZ: Option<SV>,
    ZZ: Option<SV>,
    MX: Option<SV>,
    MY: Option<SV>,
    MZ: Option<SV>,
    M: Option<SV>,
    IA: Option<SV>,
    FS: Option<SV>,
    FV: Option<SV>,
    FX: Option<SV>,
    FY: Option<SV>,
    FZ: Option<SV>,
    CX: Option<SV>,
    CY: Option<SV>,
    CZ: Option<SV>,
}

impl LinkTable {
    fn params(&self) -> [&Option<SV>; 13] {
        [
            &self.XX, &self.XY, &self.XZ, &self.YY, &self.YZ, &self.ZZ, &self.MX, &self.MY,
            &self.MZ, &self.M, &self.IA, &self.FS, &self.FV,
        ]
    }
    fn wrench(&self) -> [&Option<SV>; 6] {
        [&self.FX, &self.FY, &self.FZ, &self.CX, &self.CY, &self.CZ]
    }
}

/// Whether `s` can name a symbol in an expression: a letter or `_`, then letters, digits, `_`.
pub(crate) fn is_symbol_name(s: &str) -> bool {
    let mut c = s.chars();
    c.next()
        .is_some_and(|f| f.is_ascii_alphabetic() || f == '_')
        && c.all(|x| x.is_ascii_alphanumeric() || x == '_')
}

/// The reading of one file: its text, lines and the map being built.
struct Reader<'a> {
    text: &'a str,
    file: Option<&'a str>,
    lines: LineIndex,
    map: SourceMap,
}

impl<'a> Reader<'a> {
    fn new(text: &'a str, file: Option<&'a str>) -> Reader<'a> {
        Reader {
            text,
            file,
            lines: LineIndex::new(text),
            map: SourceMap::new(file),
        }
    }

    fn line(&self, span: Range<usize>) -> usize {
        self.lines.line(span.start)
    }

    fn err(&self, span: Range<usize>, reason: impl Into<String>) -> Error {
        Error::parse(self.file, self.line(span), reason)
    }

    /// The file as TOML: a syntax or type error names its line, the table and the key.
    fn deserialize(&self) -> Result<FileTop> {
        toml::from_str(self.text).map_err(|e| {
            let (line, column, key) = match e.span() {
                Some(s) => {
                    let (l, c) = self.lines.position(s.start);
                    (Some(l), Some(c), self.key_at(s.start))
                }
                None => (None, None, None),
            };
            let reason = friendly_toml_message(e.message());
            Error::Parse {
                location: Location {
                    file: self.file.map(str::to_string),
                    line,
                    column,
                },
                reason: match key {
                    Some(k) => format!("{k}: {reason}"),
                    None => reason,
                },
            }
        })
    }

    /// The key written on the line of `offset` (`ant`, `gravity`...) with its table (`[[frame]]`
    /// number 3, `[symbols]`), for error messages.
    fn key_at(&self, offset: usize) -> Option<String> {
        let line = self.lines.line(offset);
        let start = self.lines.line_start(line);
        let text = &self.text[start..];
        let text = &text[..text.find('\n').unwrap_or(text.len())];
        let key = text
            .split_once('=')
            .map(|(k, _)| k.trim().trim_matches(['"', '\'']).to_string())
            .filter(|k| !k.is_empty() && !k.starts_with('['));
        // the enclosing table: the last header line before, and how many like it precede
        let before = &self.text[..start];
        let header = before
            .lines()
            .rev()
            .map(str::trim)
            .find(|l| l.starts_with('['))
            .map(|h| h.split('#').next().unwrap_or(h).trim().to_string());
        let table = header.map(|h| {
            if h.starts_with("[[") {
                let n = before.lines().filter(|l| l.trim().starts_with(&h)).count();
                let name = h.trim_matches(['[', ']']).trim();
                format!("[[{name}]] number {n}")
            } else {
                h
            }
        });
        match (table, key) {
            (Some(t), Some(k)) => Some(format!("{t}, key `{k}`")),
            (None, Some(k)) => Some(format!("key `{k}`")),
            (Some(t), None) => Some(t),
            (None, None) => None,
        }
    }

    /// A value as an expression: a finite number or a string that parses.
    fn expr(&self, key: &str, v: &SV) -> Result<Expr> {
        match v.get_ref() {
            Value::Int(i) => Ok(Expr::int(*i)),
            Value::Float(x) if x.is_finite() => Ok(Expr::num(*x)),
            Value::Float(x) => {
                Err(self.err(v.span(), format!("{key}: {x} is not a finite number")))
            }
            Value::Str(s) => Expr::parse(s)
                .map_err(|e| self.err(v.span(), format!("{key}: bad expression `{s}`: {e}"))),
        }
    }

    /// NL and NJ, checked against the tables the file has before anything is sized from them.
    fn counts(&self, top: &FileTop) -> Result<(usize, usize)> {
        let nl = top
            .nl
            .as_ref()
            .map(|s| *s.get_ref())
            .unwrap_or(top.link.len());
        let nj = top.nj.as_ref().map(|s| *s.get_ref()).unwrap_or(nl);
        let nj_line = || top.nj.as_ref().map(|s| self.line(s.span())).unwrap_or(1);
        let last_line = |spans: &mut dyn Iterator<Item = Range<usize>>| {
            spans.last().map(|s| self.lines.line(s.start)).unwrap_or(1)
        };
        if top.link.len() != nl {
            return Err(Error::parse(
                self.file,
                last_line(&mut top.link.iter().map(|l| l.span())),
                format!(
                    "{} [[link]] tables given, nl = {nl} expected",
                    top.link.len()
                ),
            ));
        }
        if nj < nl {
            return Err(Error::parse(
                self.file,
                nj_line(),
                format!("nj = {nj} is smaller than nl = {nl}"),
            ));
        }
        let Some(nf) = nj.checked_mul(2).and_then(|x| x.checked_sub(nl)) else {
            return Err(Error::parse(
                self.file,
                nj_line(),
                format!("nj = {nj} is too large (NF = 2 nj - nl overflows)"),
            ));
        };
        if top.frame.len() != nf {
            return Err(Error::parse(
                self.file,
                last_line(&mut top.frame.iter().map(|f| f.span())),
                format!(
                    "{} [[frame]] tables given, NF = 2 nj - nl = {nf} expected (nl = {nl}, nj = {nj})",
                    top.frame.len()
                ),
            ));
        }
        Ok((nl, nj))
    }

    /// `[symbols]`: constant values (numbers or constant expressions such as `"pi/6"`).
    fn symbols(&mut self, top: &FileTop, desc: &mut RobotDescription) -> Result<()> {
        for (name, v) in &top.symbols {
            let line = self.line(v.span());
            self.map.set_symbol(name, line);
            if !is_symbol_name(name) {
                return Err(Error::parse(
                    self.file,
                    line,
                    format!(
                        "[symbols]: `{name}` is not a symbol name (a letter or `_`, then \
                         letters, digits or `_`)"
                    ),
                ));
            }
            let x = match v.get_ref() {
                Value::Int(i) => *i as f64,
                Value::Float(x) => *x,
                Value::Str(s) => {
                    // a symbol may be defined by an expression of the constants (e.g. "pi/6")
                    let e = Expr::parse(s).map_err(|e| {
                        Error::parse(self.file, line, format!("symbol {name}: {e}"))
                    })?;
                    e.eval(&|_| None).map_err(|e| {
                        Error::parse(
                            self.file,
                            line,
                            format!("symbol {name}: {e} (symbol values must be constants)"),
                        )
                    })?
                }
            };
            if !x.is_finite() {
                return Err(Error::parse(
                    self.file,
                    line,
                    format!("symbol {name} = {x} is not a finite number"),
                ));
            }
            desc.symbols.insert(name.clone(), x);
        }
        Ok(())
    }

    /// Check that a table's `j`, when given, is its position.
    fn check_number(&self, kind: &str, j: usize, given: &Option<Spanned<usize>>) -> Result<()> {
        match given {
            Some(jj) if *jj.get_ref() != j => Err(self.err(
                jj.span(),
                format!(
                    "[[{kind}]] number {j} says j = {}: {kind}s must be listed in order",
                    jj.get_ref()
                ),
            )),
            _ => Ok(()),
        }
    }

    fn frames(&mut self, top: &FileTop, desc: &mut RobotDescription) -> Result<()> {
        let (nl, nj) = (desc.nl, desc.nj);
        for (idx, ft) in top.frame.iter().enumerate() {
            let j = idx + 1;
            self.map.set_frame(j, None, self.line(ft.span()));
            let f = ft.get_ref();
            self.check_number("frame", j, &f.j)?;
            let joint = match (&f.sigma, &f.kind) {
                (Some(s), _) => JointType::from_sigma(*s.get_ref()).ok_or_else(|| {
                    self.err(
                        s.span(),
                        format!(
                            "frame {j}: sigma = {} (0 revolute, 1 prismatic, 2 fixed)",
                            s.get_ref()
                        ),
                    )
                })?,
                (None, Some(k)) => match k.get_ref().as_str() {
                    "revolute" => JointType::Revolute,
                    "prismatic" => JointType::Prismatic,
                    "fixed" => JointType::Fixed,
                    other => {
                        return Err(self.err(
                            k.span(),
                            format!("frame {j}: type `{other}` (revolute, prismatic or fixed)"),
                        ))
                    }
                },
                (None, None) if j > nj => JointType::Fixed,
                (None, None) => JointType::Revolute,
            };
            let actuated = match &f.mu {
                Some(m) => match m.get_ref() {
                    0 => false,
                    1 => true,
                    other => {
                        return Err(self.err(
                            m.span(),
                            format!("frame {j}: mu = {other} (1 actuated, 0 passive)"),
                        ))
                    }
                },
                None => j <= nl && joint.is_movable(),
            };
            self.map.set_frame(j, Some("ant"), self.line(f.ant.span()));
            let fr = desc.frame_mut(j);
            if let Some(n) = &f.name {
                fr.name = n.clone();
            }
            fr.ant = *f.ant.get_ref();
            fr.joint = joint;
            fr.actuated = actuated;
            let vals = [&f.gamma, &f.b, &f.alpha, &f.d, &f.theta, &f.r];
            for (k, v) in vals.iter().enumerate() {
                if let Some(v) = v {
                    let pname = GEOMETRIC_PARAMETERS[k];
                    self.map.set_frame(j, Some(pname), self.line(v.span()));
                    *desc.frame_mut(j).geometric_mut()[k] =
                        self.expr(&format!("frame {j}, {pname}"), v)?;
                }
            }
            if let Some(l) = &f.limits {
                let lim = self.limits(j, &desc.symbols, l)?;
                desc.limits.insert(j, lim);
            }
        }
        Ok(())
    }

    fn links(&mut self, top: &FileTop, desc: &mut RobotDescription) -> Result<()> {
        for (idx, lt) in top.link.iter().enumerate() {
            let j = idx + 1;
            self.map.set_link(j, None, self.line(lt.span()));
            self.check_number("link", j, &lt.get_ref().j)?;
            desc.links[idx] = self.link_desc(j, lt.get_ref())?;
        }
        Ok(())
    }

    /// The link of table `l` as link `j` (0: a floating base's `[base_link]`).
    fn link_desc(&mut self, j: usize, l: &LinkTable) -> Result<LinkDesc> {
        let default = if j == 0 {
            "base".to_string()
        } else {
            format!("link{j}")
        };
        let mut ld = LinkDesc::zero(l.name.clone().unwrap_or(default));
        let entries = l
            .params()
            .into_iter()
            .zip(STANDARD_PARAMETERS)
            .chain(l.wrench().into_iter().zip(WRENCH_COMPONENTS));
        for (k, (v, pname)) in entries.enumerate() {
            if let Some(v) = v {
                self.map.set_link(j, Some(pname), self.line(v.span()));
                let e = self.expr(&format!("link {j}, {pname}"), v)?;
                if k < 13 {
                    ld.params[k] = e;
                } else {
                    ld.wrench[k - 13] = e;
                }
            }
        }
        Ok(ld)
    }

    /// `base = "fixed" | "mobile" | "floating"` (with `mobile_base`, which it may repeat but
    /// not contradict) and a floating base's `[base_link]` (link 0's parameters).
    fn base_kind(&mut self, top: &FileTop, desc: &mut RobotDescription) -> Result<()> {
        let kind = top.base.as_ref().map(|b| (b.get_ref().as_str(), b.span()));
        let floating = match kind {
            None | Some(("fixed", _)) => false,
            Some(("mobile", _)) => {
                desc.mobile_base = true;
                false
            }
            Some(("floating", span)) => {
                if desc.mobile_base {
                    return Err(self.err(
                        span,
                        "base = \"floating\" with mobile_base = true: a base is either mobile \
                         (its motion imposed) or floating (its motion from the dynamics)",
                    ));
                }
                true
            }
            Some((other, span)) => {
                return Err(self.err(
                    span,
                    format!("base = \"{other}\": expected \"fixed\", \"mobile\" or \"floating\""),
                ))
            }
        };
        if matches!(
            top.base.as_ref().map(|b| b.get_ref().as_str()),
            Some("fixed")
        ) && desc.mobile_base
        {
            let span = top.base.as_ref().expect("given").span();
            return Err(self.err(span, "base = \"fixed\" with mobile_base = true"));
        }
        match (&top.base_link, floating) {
            (Some(bl), true) => {
                self.map.set_link(0, None, self.line(bl.span()));
                self.check_number("link", 0, &bl.get_ref().j)?;
                desc.floating_base = Some(self.link_desc(0, bl.get_ref())?);
            }
            (None, true) => desc.floating_base = Some(LinkDesc::zero("base")),
            (Some(bl), false) => {
                return Err(self.err(
                    bl.span(),
                    "[base_link] gives the parameters of a floating base: add base = \"floating\"",
                ))
            }
            (None, false) => {}
        }
        Ok(())
    }

    /// Gravity and the base velocities and accelerations: three entries each.
    fn base(&mut self, top: &FileTop, desc: &mut RobotDescription) -> Result<()> {
        for (name, v, dst) in [
            ("G", &top.gravity, &mut desc.gravity),
            ("W0", &top.w0, &mut desc.w0),
            ("WP0", &top.wp0, &mut desc.wp0),
            ("V0", &top.v0, &mut desc.v0),
            ("VP0", &top.vp0, &mut desc.vp0),
        ] {
            let Some(v) = v else { continue };
            let key = if name == "G" {
                "gravity".to_string()
            } else {
                name.to_lowercase()
            };
            self.map.set_base(name, self.line(v.span()));
            if v.get_ref().len() != 3 {
                return Err(self.err(
                    v.span(),
                    format!("{key} has {} entries, 3 expected", v.get_ref().len()),
                ));
            }
            for (k, e) in v.get_ref().iter().enumerate() {
                dst[k] = self.expr(&format!("{key}[{}]", k + 1), e)?;
            }
        }
        Ok(())
    }

    /// `assembly`: constant joint values of the tree joints (their number is checked with the
    /// structure).
    fn assembly(&mut self, top: &FileTop, desc: &mut RobotDescription) -> Result<()> {
        let Some(v) = &top.assembly else {
            return Ok(());
        };
        self.map.set_base("assembly", self.line(v.span()));
        let mut q = Vec::with_capacity(v.get_ref().len());
        for (k, e) in v.get_ref().iter().enumerate() {
            let what = format!("assembly[{}]", k + 1);
            let x = self.expr(&what, e)?.eval(&|_| None).map_err(|err| {
                self.err(
                    e.span(),
                    format!("{what}: {err} (joint values must be constants)"),
                )
            })?;
            q.push(x);
        }
        desc.assembly = Some(q);
        Ok(())
    }
}

/// serde's wording of a type error, in the words of the format.
fn friendly_toml_message(m: &str) -> String {
    m.replace(
        "data did not match any variant of untagged enum Value",
        "expected a number or a string holding an expression",
    )
    .replace("expected usize", "expected a non-negative whole number")
    .replace("expected i64", "expected a whole number")
    .replace("expected a boolean", "expected true or false")
}

/// Parse a TOML robot description. `file` names the source in error messages.
pub fn parse_description(text: &str, file: Option<&str>) -> Result<(RobotDescription, SourceMap)> {
    let mut r = Reader::new(text, file);
    let top = r.deserialize()?;
    let (nl, nj) = r.counts(&top)?;
    let mut desc =
        RobotDescription::new(top.name.clone().unwrap_or_else(|| "robot".into()), nl, nj);
    desc.notes = top.notes.clone().unwrap_or_default();
    desc.mobile_base = top.mobile_base.unwrap_or(false);
    r.symbols(&top, &mut desc)?;
    r.frames(&top, &mut desc)?;
    r.links(&top, &mut desc)?;
    r.base_kind(&top, &mut desc)?;
    r.base(&top, &mut desc)?;
    r.assembly(&top, &mut desc)?;
    if let Some(t) = &top.transmission {
        desc.transmission = Some(r.transmission(&desc, t)?);
    }
    r.tools(&top, &mut desc)?;
    validate_structure(&desc).map_err(|e| r.map.locate(e))?;
    Ok((desc, r.map))
}

impl Reader<'_> {
    /// A constant (number or expression over the file's symbols).
    fn constant(&self, key: &str, symbols: &BTreeMap<String, f64>, v: &SV) -> Result<f64> {
        self.expr(key, v)?
            .eval(&|s| symbols.get(s).copied())
            .map_err(|e| self.err(v.span(), format!("{key}: {e}")))
    }

    /// `limits = {..}` of frame j.
    fn limits(
        &self,
        j: usize,
        symbols: &BTreeMap<String, f64>,
        l: &Spanned<LimitsTable>,
    ) -> Result<JointLimits> {
        let span = l.span();
        let t = l.get_ref();
        let key = format!("frame {j}, limits");
        let c = |v: &SV| self.constant(&key, symbols, v);
        let positive = |name: &str, v: &Option<SV>| -> Result<Option<f64>> {
            match v {
                Some(v) => {
                    let x = c(v)?;
                    if x > 0.0 {
                        Ok(Some(x))
                    } else {
                        Err(self.err(
                            v.span(),
                            format!("frame {j}, limits: {name} = {x} must be positive"),
                        ))
                    }
                }
                None => Ok(None),
            }
        };
        let (q_min, q_max) = match &t.q {
            Some(q) if q.len() == 2 => {
                let (a, b) = (c(&q[0])?, c(&q[1])?);
                if a >= b {
                    return Err(self.err(
                        span,
                        format!("frame {j}, limits: q = [{a}, {b}] is not an interval [min, max]"),
                    ));
                }
                (Some(a), Some(b))
            }
            Some(q) => {
                return Err(self.err(
                    span,
                    format!(
                        "frame {j}, limits: q has {} entries, [min, max] expected",
                        q.len()
                    ),
                ))
            }
            None => (None, None),
        };
        Ok(JointLimits {
            q_min,
            q_max,
            qd: positive("qd", &t.qd)?,
            qdd: positive("qdd", &t.qdd)?,
            tau: positive("tau", &t.tau)?,
        })
    }

    /// `[transmission]`: m = R q over the actuated joints.
    fn transmission(
        &self,
        desc: &RobotDescription,
        t: &Spanned<TransmissionTable>,
    ) -> Result<Transmission> {
        let span = t.span();
        let tt = t.get_ref();
        let joints = tt.joints.clone().unwrap_or_else(|| desc.actuated_joints());
        let n = joints.len();
        if let Some(&j) = joints
            .iter()
            .find(|&&j| j == 0 || j > desc.nl || !desc.frame(j).actuated)
        {
            return Err(self.err(
                span.clone(),
                format!(
                    "transmission: joint {j} is not an actuated joint of the tree (1..{})",
                    desc.nl
                ),
            ));
        }
        if tt.matrix.len() != n {
            return Err(self.err(
            span.clone(),
            format!(
                "transmission: matrix has {} rows, {n} expected (one per motor, as many as joints {joints:?})",
                tt.matrix.len()
            ),
        ));
        }
        let mut matrix = Vec::with_capacity(n);
        for (k, row) in tt.matrix.iter().enumerate() {
            if row.len() != n {
                return Err(self.err(
                    span.clone(),
                    format!(
                        "transmission: row {} has {} entries, {n} expected",
                        k + 1,
                        row.len()
                    ),
                ));
            }
            matrix.push(
                row.iter()
                    .map(|v| self.constant("transmission, matrix", &desc.symbols, v))
                    .collect::<Result<Vec<f64>>>()?,
            );
        }
        Ok(Transmission { joints, matrix })
    }
}

impl Reader<'_> {
    /// `[[tool]]` tables: name, the frame (number, frame name or link name), xyz and rpy
    /// constants; each line recorded for the structure's checks ([`crate::model::tool_item`]).
    fn tools(&mut self, top: &FileTop, desc: &mut RobotDescription) -> Result<()> {
        for tt in &top.tool {
            let t = tt.get_ref();
            let name = t.name.get_ref().clone();
            let key = format!("tool `{name}`");
            self.map.set_base(&key, self.line(tt.span()));
            let frame = self.tool_frame(&key, desc, &t.frame)?;
            let three = |v: &Option<Spanned<Vec<SV>>>, what: &str| -> Result<[f64; 3]> {
                let Some(v) = v else { return Ok([0.0; 3]) };
                if v.get_ref().len() != 3 {
                    return Err(self.err(
                        v.span(),
                        format!(
                            "{key}: {what} has {} entries, 3 expected",
                            v.get_ref().len()
                        ),
                    ));
                }
                let mut out = [0.0; 3];
                for (k, e) in v.get_ref().iter().enumerate() {
                    out[k] = self.constant(&format!("{key}, {what}"), &desc.symbols, e)?;
                }
                Ok(out)
            };
            let tool = Tool {
                name,
                frame,
                xyz: three(&t.xyz, "xyz")?,
                rpy: three(&t.rpy, "rpy")?,
            };
            desc.tools.push(tool);
        }
        Ok(())
    }

    /// The frame number of a tool's `frame`: a number, or the name of a frame or of a link
    /// (link j is on frame j).
    fn tool_frame(
        &self,
        key: &str,
        desc: &RobotDescription,
        f: &Spanned<FrameRef>,
    ) -> Result<usize> {
        match f.get_ref() {
            FrameRef::Number(n) => usize::try_from(*n)
                .map_err(|_| self.err(f.span(), format!("{key}: frame {n} is not a frame number"))),
            FrameRef::Name(n) => {
                let by_frame = desc.frames.iter().position(|fr| &fr.name == n);
                let by_link = desc.links.iter().position(|l| &l.name == n);
                by_frame.or(by_link).map(|i| i + 1).ok_or_else(|| {
                    self.err(f.span(), format!("{key}: no frame or link is named `{n}`"))
                })
            }
        }
    }
}

/// Read a TOML robot and validate it into a [`Robot`] (every symbol needs a value).
pub fn parse_robot(text: &str, file: Option<&str>) -> Result<Robot> {
    let (desc, map) = parse_description(text, file)?;
    Robot::new(desc).map_err(|e| map.locate(e))
}

/// A TOML string literal (quotes and escapes as TOML wants them, any character kept).
fn toml_string(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

/// A value as it reads back to the same expression: an integer as a TOML integer, a float or
/// a rational with an exact decimal (`0.705`, read as 141/200) as a TOML float, anything else
/// (`1/3`, `pi/2`, `d3 + 0.1`) as an expression string, decimals where they are exact.
fn fmt_value(e: &Expr) -> String {
    match e.node() {
        Node::Rational(r) if r.is_integer() => r.numer().to_string(),
        Node::Float(x) => format!("{x:?}"),
        _ => {
            let t = e.decimal().to_string();
            if e.is_number() && t.parse::<f64>().is_ok() {
                t
            } else {
                toml_string(&t)
            }
        }
    }
}

/// Write a description in the TOML format.
pub fn write_description(desc: &RobotDescription) -> String {
    let mut s = String::new();
    s.push_str(&format!("name = {}\n", toml_string(&desc.name)));
    if !desc.notes.is_empty() {
        s.push_str("notes = [\n");
        for n in &desc.notes {
            s.push_str(&format!("  {},\n", toml_string(n)));
        }
        s.push_str("]\n");
    }
    s.push_str(&format!("nl = {}\nnj = {}\n", desc.nl, desc.nj));
    if desc.mobile_base {
        s.push_str("mobile_base = true\n");
    }
    if desc.floating_base.is_some() {
        s.push_str("base = \"floating\"\n");
    }
    let arr = |a: &[Expr; 3]| {
        format!(
            "[{}]",
            a.iter().map(fmt_value).collect::<Vec<_>>().join(", ")
        )
    };
    s.push_str(&format!("gravity = {}\n", arr(&desc.gravity)));
    for (name, v) in [
        ("w0", &desc.w0),
        ("wp0", &desc.wp0),
        ("v0", &desc.v0),
        ("vp0", &desc.vp0),
    ] {
        if v.iter().any(|e| !e.is_zero()) {
            s.push_str(&format!("{name} = {}\n", arr(v)));
        }
    }
    if let Some(q) = &desc.assembly {
        let v: Vec<String> = q.iter().map(|x| format!("{x:?}")).collect();
        s.push_str(&format!("assembly = [{}]\n", v.join(", ")));
    }
    if !desc.symbols.is_empty() {
        s.push_str("\n[symbols]\n");
        for (k, v) in &desc.symbols {
            let key = if is_symbol_name(k) {
                k.clone()
            } else {
                toml_string(k)
            };
            s.push_str(&format!("{key} = {v:?}\n"));
        }
    }
    for (idx, f) in desc.frames.iter().enumerate() {
        s.push_str(&format!(
            "\n[[frame]]\nj = {}\nname = {}\nant = {}\nsigma = {}\nmu = {}\n",
            idx + 1,
            toml_string(&f.name),
            f.ant,
            f.joint.sigma(),
            u8::from(f.actuated)
        ));
        for (k, e) in f.geometric().iter().enumerate() {
            if !e.is_zero() {
                s.push_str(&format!("{} = {}\n", GEOMETRIC_PARAMETERS[k], fmt_value(e)));
            }
        }
        if let Some(l) = desc.limits.get(&(idx + 1)) {
            let mut parts = Vec::new();
            if let (Some(a), Some(b)) = (l.q_min, l.q_max) {
                parts.push(format!("q = [{a:?}, {b:?}]"));
            }
            for (name, v) in [("qd", l.qd), ("qdd", l.qdd), ("tau", l.tau)] {
                if let Some(v) = v {
                    parts.push(format!("{name} = {v:?}"));
                }
            }
            s.push_str(&format!("limits = {{ {} }}\n", parts.join(", ")));
        }
    }
    let base = desc.floating_base.iter().map(|l| (0, l));
    for (j, l) in base.chain(desc.links.iter().enumerate().map(|(i, l)| (i + 1, l))) {
        let table = if j == 0 { "[base_link]" } else { "[[link]]" };
        s.push_str(&format!(
            "\n{table}\nj = {j}\nname = {}\n",
            toml_string(&l.name)
        ));
        for (k, e) in l.params.iter().enumerate() {
            if !e.is_zero() {
                s.push_str(&format!("{} = {}\n", STANDARD_PARAMETERS[k], fmt_value(e)));
            }
        }
        for (k, e) in l.wrench.iter().enumerate() {
            if !e.is_zero() {
                s.push_str(&format!("{} = {}\n", WRENCH_COMPONENTS[k], fmt_value(e)));
            }
        }
    }
    if let Some(t) = &desc.transmission {
        let rows: Vec<String> = t
            .matrix
            .iter()
            .map(|r| {
                let v: Vec<String> = r.iter().map(|x| format!("{x:?}")).collect();
                format!("  [{}],", v.join(", "))
            })
            .collect();
        s.push_str(&format!(
            "\n[transmission]\njoints = {:?}\nmatrix = [\n{}\n]\n",
            t.joints,
            rows.join("\n")
        ));
    }
    for t in &desc.tools {
        let [x, y, z] = t.xyz;
        let [r, p, w] = t.rpy;
        s.push_str(&format!(
            "\n[[tool]]\nname = {}\nframe = {}\nxyz = [{x:?}, {y:?}, {z:?}]\nrpy = [{r:?}, {p:?}, {w:?}]\n",
            toml_string(&t.name),
            t.frame
        ));
    }
    s
}
