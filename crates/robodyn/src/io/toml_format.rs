//! The native TOML robot format (documented in `docs/robot-format.md`).
//!
//! Every value may be a number or a string holding an expression over the symbols of the
//! `[symbols]` table. Errors carry the file and line of the offending entry.

use crate::error::{Error, Item, Location, Result};
use crate::model::{
    validate_structure, JointLimits, JointType, LinkDesc, RobotDescription, Transmission,
    GEOMETRIC_PARAMETERS, STANDARD_PARAMETERS, WRENCH_COMPONENTS,
};
use crate::Robot;
use robodyn_symbolic::Expr;
use serde::Deserialize;
use std::collections::{BTreeMap, HashMap};
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

/// Line numbers of the items of a file, to place errors found after parsing.
#[derive(Default, Debug, Clone)]
pub struct SourceMap {
    pub file: Option<String>,
    lines: HashMap<ItemKey, usize>,
}

#[derive(Hash, PartialEq, Eq, Debug, Clone)]
enum ItemKey {
    Frame(usize, Option<String>),
    Link(usize, Option<String>),
    Base(String),
    Symbol(String),
}

impl SourceMap {
    /// Record the line of an item (frame j or link j, optionally one of its parameters).
    pub fn set_frame(&mut self, j: usize, param: Option<&str>, line: usize) {
        self.lines
            .insert(ItemKey::Frame(j, param.map(str::to_string)), line);
    }
    pub fn set_link(&mut self, j: usize, param: Option<&str>, line: usize) {
        self.lines
            .insert(ItemKey::Link(j, param.map(str::to_string)), line);
    }
    pub fn set_base(&mut self, name: &str, line: usize) {
        self.lines.insert(ItemKey::Base(name.to_string()), line);
    }
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

    /// Attach file and line to an error.
    pub fn locate(&self, e: Error) -> Error {
        let line = e.item().and_then(|i| self.line_of(i));
        e.at(self.file.as_deref(), line)
    }
}

fn line_of(text: &str, span: Range<usize>) -> usize {
    text[..span.start.min(text.len())].matches('\n').count() + 1
}

fn to_expr(text: &str, file: Option<&str>, v: &SV) -> Result<Expr> {
    let line = line_of(text, v.span());
    match v.get_ref() {
        Value::Int(i) => Ok(Expr::int(*i)),
        Value::Float(x) => {
            if x.is_finite() {
                Ok(Expr::num(*x))
            } else {
                Err(Error::parse(
                    file,
                    line,
                    format!("{x} is not a finite number"),
                ))
            }
        }
        Value::Str(s) => Expr::parse(s)
            .map_err(|e| Error::parse(file, line, format!("bad expression `{s}`: {e}"))),
    }
}

/// Parse a TOML robot description. `file` names the source in error messages.
pub fn parse_description(text: &str, file: Option<&str>) -> Result<(RobotDescription, SourceMap)> {
    let top: FileTop = toml::from_str(text).map_err(|e| {
        let line = e.span().map(|s| line_of(text, s)).unwrap_or(1);
        Error::Parse {
            location: Location {
                file: file.map(str::to_string),
                line: Some(line),
                column: None,
            },
            reason: e.message().to_string(),
        }
    })?;
    let mut map = SourceMap {
        file: file.map(str::to_string),
        ..Default::default()
    };
    let nl = top
        .nl
        .as_ref()
        .map(|s| *s.get_ref())
        .unwrap_or(top.link.len());
    let nj = top.nj.as_ref().map(|s| *s.get_ref()).unwrap_or(nl);
    if nj < nl || 2 * nj < nl {
        let line = top
            .nj
            .as_ref()
            .map(|s| line_of(text, s.span()))
            .unwrap_or(1);
        return Err(Error::parse(
            file,
            line,
            format!("nj = {nj} is smaller than nl = {nl}"),
        ));
    }
    let mut desc =
        RobotDescription::new(top.name.clone().unwrap_or_else(|| "robot".into()), nl, nj);
    desc.notes = top.notes.clone().unwrap_or_default();
    desc.mobile_base = top.mobile_base.unwrap_or(false);
    let nf = desc.nf();
    if top.frame.len() != nf {
        return Err(Error::parse(
            file,
            top.frame
                .last()
                .map(|f| line_of(text, f.span()))
                .unwrap_or(1),
            format!(
                "{} [[frame]] tables given, NF = 2 nj - nl = {nf} expected (nl = {nl}, nj = {nj})",
                top.frame.len()
            ),
        ));
    }
    if top.link.len() != nl {
        return Err(Error::parse(
            file,
            top.link
                .last()
                .map(|f| line_of(text, f.span()))
                .unwrap_or(1),
            format!(
                "{} [[link]] tables given, nl = {nl} expected",
                top.link.len()
            ),
        ));
    }
    for (name, v) in &top.symbols {
        let line = line_of(text, v.span());
        map.set_symbol(name, line);
        let x = match v.get_ref() {
            Value::Int(i) => *i as f64,
            Value::Float(x) => *x,
            Value::Str(s) => {
                // a symbol may be defined by an expression of the constants (e.g. "pi/6")
                let e = Expr::parse(s)
                    .map_err(|e| Error::parse(file, line, format!("symbol {name}: {e}")))?;
                e.eval(&|_| None).map_err(|e| {
                    Error::parse(
                        file,
                        line,
                        format!("symbol {name}: {e} (symbol values must be constants)"),
                    )
                })?
            }
        };
        if !x.is_finite() {
            return Err(Error::parse(
                file,
                line,
                format!("symbol {name} = {x} is not a finite number"),
            ));
        }
        desc.symbols.insert(name.clone(), x);
    }
    for (idx, ft) in top.frame.iter().enumerate() {
        let j = idx + 1;
        let line = line_of(text, ft.span());
        map.set_frame(j, None, line);
        let f = ft.get_ref();
        if let Some(jj) = &f.j {
            if *jj.get_ref() != j {
                return Err(Error::parse(
                    file,
                    line_of(text, jj.span()),
                    format!(
                        "[[frame]] number {j} says j = {}: frames must be listed in order",
                        jj.get_ref()
                    ),
                ));
            }
        }
        let fr = desc.frame_mut(j);
        if let Some(n) = &f.name {
            fr.name = n.clone();
        }
        fr.ant = *f.ant.get_ref();
        map.set_frame(j, Some("ant"), line_of(text, f.ant.span()));
        let joint = match (&f.sigma, &f.kind) {
            (Some(s), _) => JointType::from_sigma(*s.get_ref()).ok_or_else(|| {
                Error::parse(
                    file,
                    line_of(text, s.span()),
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
                    return Err(Error::parse(
                        file,
                        line_of(text, k.span()),
                        format!("frame {j}: type `{other}` (revolute, prismatic or fixed)"),
                    ))
                }
            },
            (None, None) => {
                if j > nj {
                    JointType::Fixed
                } else {
                    JointType::Revolute
                }
            }
        };
        fr.joint = joint;
        fr.actuated = match &f.mu {
            Some(m) => match m.get_ref() {
                0 => false,
                1 => true,
                other => {
                    return Err(Error::parse(
                        file,
                        line_of(text, m.span()),
                        format!("frame {j}: mu = {other} (1 actuated, 0 passive)"),
                    ))
                }
            },
            None => j <= nl && joint.is_movable(),
        };
        let vals = [&f.gamma, &f.b, &f.alpha, &f.d, &f.theta, &f.r];
        for (k, v) in vals.iter().enumerate() {
            if let Some(v) = v {
                map.set_frame(j, Some(GEOMETRIC_PARAMETERS[k]), line_of(text, v.span()));
                *desc.frame_mut(j).geometric_mut()[k] = to_expr(text, file, v)?;
            }
        }
        if let Some(l) = &f.limits {
            let lim = parse_limits(text, file, &desc.symbols, l)?;
            desc.limits.insert(j, lim);
        }
    }
    for (idx, lt) in top.link.iter().enumerate() {
        let j = idx + 1;
        let line = line_of(text, lt.span());
        map.set_link(j, None, line);
        let l = lt.get_ref();
        if let Some(jj) = &l.j {
            if *jj.get_ref() != j {
                return Err(Error::parse(
                    file,
                    line_of(text, jj.span()),
                    format!(
                        "[[link]] number {j} says j = {}: links must be listed in order",
                        jj.get_ref()
                    ),
                ));
            }
        }
        let mut ld = LinkDesc::zero(l.name.clone().unwrap_or_else(|| format!("link{j}")));
        for (k, v) in l.params().iter().enumerate() {
            if let Some(v) = v {
                map.set_link(j, Some(STANDARD_PARAMETERS[k]), line_of(text, v.span()));
                ld.params[k] = to_expr(text, file, v)?;
            }
        }
        for (k, v) in l.wrench().iter().enumerate() {
            if let Some(v) = v {
                map.set_link(j, Some(WRENCH_COMPONENTS[k]), line_of(text, v.span()));
                ld.wrench[k] = to_expr(text, file, v)?;
            }
        }
        desc.links[idx] = ld;
    }
    for (name, v, dst) in [
        ("G", &top.gravity, &mut desc.gravity),
        ("W0", &top.w0, &mut desc.w0),
        ("WP0", &top.wp0, &mut desc.wp0),
        ("V0", &top.v0, &mut desc.v0),
        ("VP0", &top.vp0, &mut desc.vp0),
    ] {
        if let Some(v) = v {
            let line = line_of(text, v.span());
            map.set_base(name, line);
            if v.get_ref().len() != 3 {
                return Err(Error::parse(
                    file,
                    line,
                    format!(
                        "{} has {} entries, 3 expected",
                        name.to_lowercase(),
                        v.get_ref().len()
                    ),
                ));
            }
            for (k, e) in v.get_ref().iter().enumerate() {
                dst[k] = to_expr(text, file, e)?;
            }
        }
    }
    if let Some(v) = &top.assembly {
        let line = line_of(text, v.span());
        map.set_base("assembly", line);
        let mut q = Vec::with_capacity(v.get_ref().len());
        for e in v.get_ref() {
            let x = to_expr(text, file, e)?.eval(&|_| None).map_err(|err| {
                Error::parse(
                    file,
                    line,
                    format!("assembly: {err} (joint values must be constants)"),
                )
            })?;
            q.push(x);
        }
        desc.assembly = Some(q);
    }
    if let Some(t) = &top.transmission {
        desc.transmission = Some(parse_transmission(text, file, &desc, t)?);
    }
    validate_structure(&desc).map_err(|e| map.locate(e))?;
    Ok((desc, map))
}

/// A constant (number or expression over the file's symbols).
fn constant(
    text: &str,
    file: Option<&str>,
    symbols: &BTreeMap<String, f64>,
    v: &SV,
) -> Result<f64> {
    to_expr(text, file, v)?
        .eval(&|s| symbols.get(s).copied())
        .map_err(|e| Error::parse(file, line_of(text, v.span()), e.to_string()))
}

fn parse_limits(
    text: &str,
    file: Option<&str>,
    symbols: &BTreeMap<String, f64>,
    l: &Spanned<LimitsTable>,
) -> Result<JointLimits> {
    let line = line_of(text, l.span());
    let t = l.get_ref();
    let c = |v: &SV| constant(text, file, symbols, v);
    let positive = |name: &str, v: &Option<SV>| -> Result<Option<f64>> {
        match v {
            Some(v) => {
                let x = c(v)?;
                if x > 0.0 {
                    Ok(Some(x))
                } else {
                    Err(Error::parse(
                        file,
                        line_of(text, v.span()),
                        format!("limits: {name} = {x} must be positive"),
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
                return Err(Error::parse(
                    file,
                    line,
                    format!("limits: q = [{a}, {b}] is not an interval [min, max]"),
                ));
            }
            (Some(a), Some(b))
        }
        Some(q) => {
            return Err(Error::parse(
                file,
                line,
                format!("limits: q has {} entries, [min, max] expected", q.len()),
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

fn parse_transmission(
    text: &str,
    file: Option<&str>,
    desc: &RobotDescription,
    t: &Spanned<TransmissionTable>,
) -> Result<Transmission> {
    let line = line_of(text, t.span());
    let tt = t.get_ref();
    let joints = tt.joints.clone().unwrap_or_else(|| desc.actuated_joints());
    let n = joints.len();
    if let Some(&j) = joints
        .iter()
        .find(|&&j| j == 0 || j > desc.nl || !desc.frame(j).actuated)
    {
        return Err(Error::parse(
            file,
            line,
            format!(
                "transmission: joint {j} is not an actuated joint of the tree (1..{})",
                desc.nl
            ),
        ));
    }
    if tt.matrix.len() != n {
        return Err(Error::parse(
            file,
            line,
            format!(
                "transmission: matrix has {} rows, {n} expected (one per motor, as many as joints {joints:?})",
                tt.matrix.len()
            ),
        ));
    }
    let mut matrix = Vec::with_capacity(n);
    for (k, row) in tt.matrix.iter().enumerate() {
        if row.len() != n {
            return Err(Error::parse(
                file,
                line,
                format!(
                    "transmission: row {} has {} entries, {n} expected",
                    k + 1,
                    row.len()
                ),
            ));
        }
        matrix.push(
            row.iter()
                .map(|v| constant(text, file, &desc.symbols, v))
                .collect::<Result<Vec<f64>>>()?,
        );
    }
    Ok(Transmission { joints, matrix })
}

/// Read a TOML robot and validate it into a [`Robot`] (every symbol needs a value).
pub fn parse_robot(text: &str, file: Option<&str>) -> Result<Robot> {
    let (desc, map) = parse_description(text, file)?;
    Robot::new(desc).map_err(|e| map.locate(e))
}

fn fmt_value(e: &Expr) -> String {
    match e.as_f64() {
        Some(x) if e.as_rational().is_some_and(|r| r.is_integer()) => format!("{x}"),
        Some(x) => format!("{x:?}"),
        None => format!("\"{e}\""),
    }
}

/// Write a description in the TOML format.
pub fn write_description(desc: &RobotDescription) -> String {
    let mut s = String::new();
    s.push_str(&format!("name = {:?}\n", desc.name));
    if !desc.notes.is_empty() {
        s.push_str("notes = [\n");
        for n in &desc.notes {
            s.push_str(&format!("  {n:?},\n"));
        }
        s.push_str("]\n");
    }
    s.push_str(&format!("nl = {}\nnj = {}\n", desc.nl, desc.nj));
    if desc.mobile_base {
        s.push_str("mobile_base = true\n");
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
            s.push_str(&format!("{k} = {v:?}\n"));
        }
    }
    for (idx, f) in desc.frames.iter().enumerate() {
        s.push_str(&format!(
            "\n[[frame]]\nj = {}\nname = {:?}\nant = {}\nsigma = {}\nmu = {}\n",
            idx + 1,
            f.name,
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
    for (idx, l) in desc.links.iter().enumerate() {
        s.push_str(&format!(
            "\n[[link]]\nj = {}\nname = {:?}\n",
            idx + 1,
            l.name
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
    s
}
