//! Emitters of a [`Program`]: SYMORO-style text, LaTeX, Rust, C99, Python/NumPy, Julia and
//! MATLAB/GNU Octave.
//!
//! Output is deterministic (assignment order, no hash-map iteration) and documents the inputs and
//! the operation counts in a header comment.

use crate::expr::{grow, Expr, Func, Node};
use crate::print::{product_parts, term_is_negative};
use crate::program::Program;
use num_traits::Signed;
use std::collections::{HashMap, HashSet};
use std::fmt::Write;

/// Target language.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lang {
    /// SYMORO-style equations `NAME = expr`, one per line.
    Text,
    /// A LaTeX `align*` environment.
    Latex,
    /// A Rust function over slices.
    Rust,
    /// A C99 function over `double` arrays.
    C,
    /// A Python function over NumPy arrays.
    Python,
    /// A Julia function filling its output in place (`NAME!`).
    Julia,
    /// MATLAB / GNU Octave: a function file `NAME.m` (1-based indexing).
    Matlab,
}

impl Lang {
    /// Every language, in the order of the documentation (what a command line or a binding
    /// offers; [`Lang::name`] is each one's name).
    pub const ALL: [Lang; 7] = [
        Lang::Text,
        Lang::Latex,
        Lang::Rust,
        Lang::C,
        Lang::Python,
        Lang::Julia,
        Lang::Matlab,
    ];

    /// The language's name: `text`, `latex`, `rust`, `c`, `python`, `julia`, `matlab`
    /// ([`Lang::from_name`] reads it back).
    pub fn name(self) -> &'static str {
        match self {
            Lang::Text => "text",
            Lang::Latex => "latex",
            Lang::Rust => "rust",
            Lang::C => "c",
            Lang::Python => "python",
            Lang::Julia => "julia",
            Lang::Matlab => "matlab",
        }
    }

    /// What [`emit`] writes in this language, in a few words.
    pub fn describe(self) -> &'static str {
        match self {
            Lang::Text => "SYMORO-style equations, one `NAME = expression` per line",
            Lang::Latex => "rows of a LaTeX align* environment (amsmath)",
            Lang::Rust => "a Rust function over slices",
            Lang::C => "a C99 function over double arrays",
            Lang::Python => "a Python function over NumPy arrays",
            Lang::Julia => "a Julia function `NAME!(out, ...)`, 1-based",
            Lang::Matlab => "a MATLAB / GNU Octave function file `NAME.m`, 1-based",
        }
    }

    /// The language of a name or file extension (`c`, `rust`/`rs`, `python`/`py`, `m`...).
    pub fn from_name(s: &str) -> Option<Lang> {
        Some(match s {
            "text" | "txt" => Lang::Text,
            "latex" | "tex" => Lang::Latex,
            "rust" | "rs" => Lang::Rust,
            "c" => Lang::C,
            "python" | "py" => Lang::Python,
            "julia" | "jl" => Lang::Julia,
            "matlab" | "octave" | "m" => Lang::Matlab,
            _ => return None,
        })
    }

    fn comment(self) -> &'static str {
        match self {
            Lang::Text | Lang::Python | Lang::Julia => "# ",
            Lang::Latex => "% ",
            Lang::Rust | Lang::C => "// ",
            Lang::Matlab => "% ",
        }
    }

    /// First index of an array: 1 in Julia and MATLAB, else 0.
    fn first_index(self) -> usize {
        usize::from(matches!(self, Lang::Julia | Lang::Matlab))
    }

    /// `array[i]`, or `array(i)` in MATLAB.
    fn index(self, array: &str, i: usize) -> String {
        if self == Lang::Matlab {
            format!("{array}({i})")
        } else {
            format!("{array}[{i}]")
        }
    }
}

/// Print a program in a language.
pub fn emit(p: &Program, lang: Lang) -> String {
    match lang {
        Lang::Text => emit_text(p),
        Lang::Latex => emit_latex(p),
        _ => emit_code(p, lang),
    }
}

/// How a group passed by name is given, for the header.
fn by_name_how(p: &Program, lang: Lang) -> String {
    match (lang, parameter_type(p, lang)) {
        (Lang::C | Lang::Rust, Some(t)) => format!("by name: a struct {t} with these fields"),
        (Lang::Python, _) => format!(
            "by name: a mapping from these names to values, e.g. dict(zip({}, values))",
            python_names_constant(p)
        ),
        (Lang::Julia, _) => "by name: any value with these fields, e.g. a NamedTuple".into(),
        (Lang::Matlab, _) => "by name: a struct with these fields".into(),
        _ => "by name".into(),
    }
}

/// The symbols of the program's groups passed by name, with the field (and variable) name the
/// generated code gives each: the symbol itself, or with a trailing underscore when the code
/// needs the name or a language reserves it (`end` -> `end_`). In the order of the header.
pub fn parameter_fields(p: &Program) -> Vec<(String, String)> {
    let names = Names::new(p);
    p.inputs
        .iter()
        .filter(|g| g.by_name)
        .flat_map(|g| g.symbols.iter().flatten())
        .map(|sym| (sym.clone(), names.get(sym)))
        .collect()
}

/// The type of the parameter record of C and Rust code (`NAME_params`, `NameParams`), when the
/// program has a group passed by name.
pub fn parameter_type(p: &Program, lang: Lang) -> Option<String> {
    if !p.inputs.iter().any(|g| g.by_name) {
        return None;
    }
    match lang {
        Lang::C => Some(format!("{}_params", p.name)),
        Lang::Rust => {
            let camel: String = p
                .name
                .split('_')
                .filter(|w| !w.is_empty())
                .map(|w| {
                    let mut c = w.chars();
                    c.next()
                        .map(|f| f.to_ascii_uppercase().to_string() + c.as_str())
                        .unwrap_or_default()
                })
                .collect();
            Some(format!("{camel}Params"))
        }
        _ => None,
    }
}

/// The Python constant listing the parameter names in order (`NAME_PARAMETERS`).
fn python_names_constant(p: &Program) -> String {
    format!("{}_PARAMETERS", p.name.to_uppercase())
}

fn header(p: &Program, lang: Lang) -> String {
    let c = lang.comment();
    let mut s = String::new();
    for line in &p.description {
        let _ = writeln!(s, "{c}{line}");
    }
    let k = p.count();
    let _ = writeln!(
        s,
        "{c}Operations: {} multiplications, {} additions ({} function calls: sin, cos, sign)",
        k.mul, k.add, k.func
    );
    let base = lang.first_index();
    let _ = writeln!(s, "{c}Inputs:");
    let names = Names::new(p);
    for g in &p.inputs {
        if g.by_name {
            let fields: Vec<String> = g
                .symbols
                .iter()
                .flatten()
                .map(|sym| match names.get(sym) {
                    f if f == *sym => f,
                    f => format!("{sym} (field {f})"),
                })
                .collect();
            let _ = writeln!(
                s,
                "{c}  {} ({}; {}): {}",
                g.name,
                g.doc,
                by_name_how(p, lang),
                fields.join(" ")
            );
            continue;
        }
        let names: Vec<String> = g
            .symbols
            .iter()
            .enumerate()
            .map(|(i, s)| match s {
                Some(s) => format!("{}={s}", lang.index(&g.name, i + base)),
                None => format!("{}=unused", lang.index(&g.name, i + base)),
            })
            .collect();
        let _ = writeln!(s, "{c}  {} ({}): {}", g.name, g.doc, names.join(" "));
    }
    let outs: Vec<String> = p
        .outputs
        .iter()
        .enumerate()
        .map(|(i, o)| format!("{}={}", lang.index("out", i + base), o.name))
        .collect();
    let _ = writeln!(s, "{c}Outputs: {}", outs.join(" "));
    s
}

fn emit_text(p: &Program) -> String {
    let mut s = header(p, Lang::Text);
    s.push('\n');
    for a in p.assignments.iter().chain(&p.outputs) {
        if !p.output_is_named(a) {
            let _ = writeln!(s, "{} = {}", a.name, a.expr);
        }
    }
    s
}

/// `WI12` -> `WI_{12}`, `XXR2` -> `XXR_{2}`, `T3` -> `T_{3}`; indices joined by underscores
/// become a list: `KP4_1_2` -> `KP_{4,1,2}`, `W3_1` -> `W_{3,1}`.
fn latex_name(n: &str) -> String {
    let i = n
        .trim_end_matches(|c: char| c.is_ascii_digit() || c == '_')
        .len();
    let (base, rest) = n.split_at(i);
    let (base, digits) = if !base.is_empty()
        && rest.starts_with(|c: char| c.is_ascii_digit())
        && rest.ends_with(|c: char| c.is_ascii_digit())
        && !rest.contains("__")
    {
        (base, rest.replace('_', ","))
    } else {
        let i = n.trim_end_matches(|c: char| c.is_ascii_digit()).len();
        (&n[..i], n[i..].to_string())
    };
    let base = base.replace('_', "\\_");
    let base = if base.len() > 1 {
        format!("\\mathit{{{base}}}")
    } else {
        base
    };
    if digits.is_empty() {
        base
    } else {
        format!("{base}_{{{digits}}}")
    }
}

fn latex(e: &Expr, prec: u8) -> String {
    grow(|| latex_node(e, prec))
}

fn latex_node(e: &Expr, prec: u8) -> String {
    match e.node() {
        Node::Rational(r) => {
            let body = if r.is_integer() {
                r.numer().abs().to_string()
            } else {
                format!("\\frac{{{}}}{{{}}}", r.numer().abs(), r.denom())
            };
            if r.is_negative() {
                if prec > 0 {
                    format!("\\left(-{body}\\right)")
                } else {
                    format!("-{body}")
                }
            } else {
                body
            }
        }
        Node::Float(x) => {
            if *x < 0.0 && prec > 0 {
                format!("\\left({x:?}\\right)")
            } else {
                format!("{x:?}")
            }
        }
        Node::Pi => "\\pi".into(),
        Node::Symbol(s) => latex_name(s),
        Node::Add(v) => {
            let s = latex_terms(v).concat();
            if prec > 0 {
                format!("\\left({s}\\right)")
            } else {
                s
            }
        }
        Node::Pow(b, n) if *n > 0 => {
            let base = latex(b, 3);
            if matches!(b.node(), Node::Pow(..)) {
                format!("\\left({base}\\right)^{{{n}}}")
            } else {
                format!("{base}^{{{n}}}")
            }
        }
        Node::Mul(_) | Node::Pow(..) => {
            let (coef, num, den) = product_parts(e);
            let mut neg = false;
            let mut parts: Vec<String> = Vec::new();
            let mut dens: Vec<String> = Vec::new();
            if let Some(c) = coef {
                let x = c.as_f64().unwrap_or(0.0);
                neg = x < 0.0;
                let a = if neg { -c } else { c };
                if let Some(r) = a.as_rational() {
                    if *r.numer() != 1 {
                        parts.push(r.numer().to_string());
                    }
                    if *r.denom() != 1 {
                        dens.push(r.denom().to_string());
                    }
                } else if !a.is_one() {
                    parts.push(latex(&a, 2));
                }
            }
            parts.extend(num.iter().map(|f| latex(f, 2)));
            dens.extend(den.iter().map(|f| latex(f, 2)));
            let n = if parts.is_empty() {
                "1".to_string()
            } else {
                parts.join("\\,")
            };
            let body = if dens.is_empty() {
                n
            } else {
                format!("\\frac{{{n}}}{{{}}}", dens.join("\\,"))
            };
            if neg {
                if prec > 0 {
                    format!("\\left(-{body}\\right)")
                } else {
                    format!("-{body}")
                }
            } else {
                body
            }
        }
        Node::Func(f, a) => {
            let name = match f {
                Func::Sin => "\\sin",
                Func::Cos => "\\cos",
                Func::Tan => "\\tan",
                Func::Sqrt => return format!("\\sqrt{{{}}}", latex(a, 0)),
                Func::Abs => return format!("\\left|{}\\right|", latex(a, 0)),
                Func::Sign => "\\operatorname{sign}",
            };
            format!("{name}\\left({}\\right)", latex(a, 0))
        }
        Node::Atan2(y, x) => format!(
            "\\operatorname{{atan2}}\\left({}, {}\\right)",
            latex(y, 0),
            latex(x, 0)
        ),
    }
}

/// The terms of a sum, each with its sign: `a`, ` + b`, ` - c`.
fn latex_terms(v: &[Expr]) -> Vec<String> {
    v.iter()
        .enumerate()
        .map(|(i, t)| {
            if i == 0 {
                latex(t, 0)
            } else if term_is_negative(t) {
                let neg = -t.clone();
                let prec = u8::from(matches!(neg.node(), Node::Add(_)));
                format!(" - {}", latex(&neg, prec))
            } else {
                format!(" + {}", latex(t, 0))
            }
        })
        .collect()
}

/// Printed width, in characters, of a line of an `align*` row (an article's text width).
const LATEX_LINE_WIDTH: usize = 48;

/// Rough printed width of LaTeX math: its characters less the markup.
fn latex_width(s: &str) -> usize {
    [
        "\\operatorname",
        "\\mathit",
        "\\left",
        "\\right",
        "\\,",
        "{",
        "}",
        "_",
        "^",
    ]
    .iter()
    .fold(s.to_string(), |acc, m| acc.replace(m, ""))
    .chars()
    .count()
}

/// The right-hand side of an assignment; a sum too wide for one line is broken between its
/// terms over several lines of the row.
fn latex_rhs(e: &Expr) -> String {
    let Node::Add(v) = e.node() else {
        return latex(e, 0);
    };
    let mut lines: Vec<String> = vec![String::new()];
    for t in latex_terms(v) {
        let line = lines.last_mut().expect("one line");
        if !line.is_empty() && latex_width(line) + latex_width(&t) > LATEX_LINE_WIDTH {
            lines.push(t);
        } else {
            line.push_str(&t);
        }
    }
    lines.join(" \\\\\n&\\qquad")
}

fn emit_latex(p: &Program) -> String {
    let mut s = header(p, Lang::Latex);
    s.push_str("\\begin{align*}\n");
    let all: Vec<_> = p
        .assignments
        .iter()
        .chain(&p.outputs)
        .filter(|a| !p.output_is_named(a))
        .collect();
    for (i, a) in all.iter().enumerate() {
        let end = if i + 1 < all.len() { " \\\\" } else { "" };
        let _ = writeln!(s, "{} &= {}{end}", latex_name(&a.name), latex_rhs(&a.expr));
    }
    s.push_str("\\end{align*}\n");
    s
}

/// Infix code for C-like languages: powers written as products, rationals as float literals.
fn code(e: &Expr, lang: Lang, prec: u8, names: &Names) -> String {
    grow(|| code_node(e, lang, prec, names))
}

fn code_node(e: &Expr, lang: Lang, prec: u8, names: &Names) -> String {
    let lit = |x: f64| -> String {
        let s = format!("{x:?}");
        let s = if s.contains('.') || s.contains('e') || s.contains("inf") || s.contains("NaN") {
            s
        } else {
            format!("{s}.0")
        };
        if x < 0.0 && prec > 0 {
            format!("({s})")
        } else {
            s
        }
    };
    match e.node() {
        Node::Rational(r) => {
            if r.is_integer() {
                lit(*r.numer() as f64)
            } else {
                let s = format!("{}/{}", lit(r.numer().abs() as f64), lit(*r.denom() as f64));
                if r.is_negative() {
                    format!("(-{s})")
                } else {
                    format!("({s})")
                }
            }
        }
        Node::Float(x) => lit(*x),
        Node::Pi => match lang {
            Lang::Rust => "std::f64::consts::PI".into(),
            Lang::C => "3.141592653589793".into(),
            Lang::Python => "np.pi".into(),
            _ => "pi".into(),
        },
        Node::Symbol(s) => names.get(s),
        Node::Add(v) => {
            let mut s = String::new();
            for (i, t) in v.iter().enumerate() {
                if i == 0 {
                    s += &code(t, lang, 0, names);
                } else if term_is_negative(t) {
                    s += " - ";
                    s += &code(&-t.clone(), lang, 1, names);
                } else {
                    s += " + ";
                    s += &code(t, lang, 0, names);
                }
            }
            if prec > 0 {
                format!("({s})")
            } else {
                s
            }
        }
        Node::Mul(_) | Node::Pow(..) => {
            let (coef, num, den) = product_parts(e);
            let mut neg = false;
            let mut parts: Vec<String> = Vec::new();
            if let Some(c) = coef {
                neg = c.as_f64().unwrap_or(0.0) < 0.0;
                let a = if neg { -c } else { c };
                if !a.is_one() {
                    parts.push(code(&a, lang, 2, names));
                }
            }
            for f in &num {
                push_power(f, lang, &mut parts, names);
            }
            let mut body = if parts.is_empty() {
                "1.0".to_string()
            } else {
                parts.join("*")
            };
            for d in &den {
                let mut dp = Vec::new();
                push_power(d, lang, &mut dp, names);
                for x in dp {
                    body = format!("{body}/{x}");
                }
            }
            if neg {
                body = format!("-{body}");
            }
            if prec > 0 && (neg || prec > 1) {
                format!("({body})")
            } else {
                body
            }
        }
        Node::Func(f, a) => {
            let arg = code(a, lang, 0, names);
            match (lang, f) {
                (Lang::Rust, Func::Sign) => format!("sgn({arg})"),
                // a literal argument has no type of its own: name the method's type
                (Lang::Rust, _) if a.is_number() => format!("f64::{}({arg})", f.name()),
                (Lang::Rust, _) => format!("({arg}).{}()", f.name()),
                (Lang::C, Func::Sign) => format!("rd_sign({arg})"),
                (Lang::C, Func::Abs) => format!("fabs({arg})"),
                (Lang::C, _) => format!("{}({arg})", f.name()),
                (Lang::Python, _) => format!("np.{}({arg})", f.name()),
                (_, _) => format!("{}({arg})", f.name()),
            }
        }
        Node::Atan2(y, x) => {
            let (y, x) = (code(y, lang, 0, names), code(x, lang, 0, names));
            match lang {
                Lang::Rust => format!("f64::atan2({y}, {x})"),
                Lang::Python => format!("np.arctan2({y}, {x})"),
                Lang::Julia => format!("atan({y}, {x})"),
                _ => format!("atan2({y}, {x})"),
            }
        }
    }
}

/// x^n written as n factors so that the code performs the counted multiplications; a power of
/// a compound base beyond the square (`(x^40)^2`, `(a + b)^3`: never in a generated model) as
/// the language's power, so that nested powers cannot multiply the length of the code.
fn push_power(f: &Expr, lang: Lang, parts: &mut Vec<String>, names: &Names) {
    match f.node() {
        Node::Pow(b, n) if *n > 0 => {
            let s = code(b, lang, 2, names);
            let leaf = matches!(b.node(), Node::Symbol(_) | Node::Pi) || b.is_number();
            if leaf || *n <= 2 {
                for _ in 0..*n {
                    parts.push(s.clone());
                }
            } else {
                parts.push(match lang {
                    Lang::C => format!("pow({s}, {n})"),
                    Lang::Rust => format!("{s}.powi({n})"),
                    Lang::Python => format!("{s}**{n}"),
                    _ => format!("{s}^{n}"),
                });
            }
        }
        _ => parts.push(code(f, lang, 2, names)),
    }
}

/// Identifiers generated code never gives a symbol: the names the code itself uses (argument
/// arrays, helpers, math functions) and the keywords of Rust, C, Python, Julia and MATLAB.
const RESERVED: &str = "\
    q qd qdd p gam out sgn rd_sign np math std f64 sin cos tan sqrt abs fabs sign pi zeros \
    Inf NaN inf nan \
    as async await break const continue crate dyn else enum extern false fn for if impl in let \
    loop match mod move mut pub ref return self Self static struct super trait true type unsafe \
    use where while abstract become box do final gen macro override priv try typeof unsized \
    virtual yield \
    auto case char default double float goto inline int long register restrict short signed \
    sizeof switch typedef union unsigned void volatile \
    False None True and assert class def del elif except finally from global import is lambda \
    nonlocal not or pass raise with \
    baremodule begin catch elseif end export function local module quote using outer isa \
    classdef otherwise parfor persistent spmd";

fn is_reserved(name: &str) -> bool {
    RESERVED.split_whitespace().any(|r| r == name)
}

/// The names the generated code itself uses in the function's scope: its arguments, helpers
/// and the math functions it calls (a function of that name would hide or clash with them).
const CODE_NAMES: &str = "q qd qdd p gam out sgn rd_sign np math sin cos tan sqrt abs fabs \
    sign atan atan2 pow zeros pi Inf NaN inf nan";

/// The reserved words of each language a function may not be named (keywords, and for C the
/// functions `math.h` declares).
fn keywords(lang: Lang) -> &'static str {
    match lang {
        Lang::Text | Lang::Latex => "",
        Lang::Rust => {
            "as async await break const continue crate dyn else enum extern false fn for gen if \
             impl in let loop match mod move mut pub ref return self Self static struct super \
             trait true type unsafe use where while abstract become box do final macro override \
             priv try typeof unsized virtual yield f64 std"
        }
        Lang::C => {
            "auto break case char const continue default do double else enum extern float for \
             goto if inline int long register restrict return short signed sizeof static struct \
             switch typedef union unsigned void volatile while _Bool _Complex _Imaginary \
             bool true false acos asin atan atan2 ceil cos cosh exp fabs floor fmod frexp ldexp \
             log log10 modf pow sin sinh sqrt tan tanh cbrt exp2 expm1 fma fmax fmin hypot \
             log1p log2 lround round trunc nan remainder"
        }
        Lang::Python => {
            "False None True and as assert async await break class continue def del elif else \
             except finally for from global if import in is lambda nonlocal not or pass raise \
             return try while with yield"
        }
        Lang::Julia => {
            "baremodule begin break catch const continue do else elseif end export false \
             finally for function global if import let local macro module quote return struct \
             true try using while abstract mutable primitive type where in isa outer public"
        }
        Lang::Matlab => {
            "break case catch classdef continue else elseif end for function global if \
             otherwise parfor persistent return spmd switch try while arguments enumeration \
             events methods properties"
        }
    }
}

/// Check a function name for generated code in `lang`: an ASCII identifier (a letter or `_`,
/// then letters, digits, `_`; MATLAB: a letter first and at most 63 characters), not a reserved
/// word of the language, and not a name the generated code uses itself (`q`, `out`, `sin`...).
/// The same rule holds for text and LaTeX, whose headers name the function. The error says
/// which rule the name breaks.
pub fn check_function_name(name: &str, lang: Lang) -> Result<(), String> {
    let language = match lang {
        Lang::Text => "text",
        Lang::Latex => "LaTeX",
        Lang::Rust => "Rust",
        Lang::C => "C",
        Lang::Python => "Python",
        Lang::Julia => "Julia",
        Lang::Matlab => "MATLAB",
    };
    let first_ok = match lang {
        Lang::Matlab => name.starts_with(|c: char| c.is_ascii_alphabetic()),
        _ => name.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_'),
    };
    if name.is_empty()
        || !first_ok
        || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        || name.chars().all(|c| c == '_')
    {
        let first = if lang == Lang::Matlab {
            "a letter"
        } else {
            "a letter or `_`"
        };
        return Err(format!(
            "`{name}` is not a {language} identifier, as a function name must be: it starts \
             with {first} and has only ASCII letters, digits and `_` (no spaces, punctuation or \
             other characters)"
        ));
    }
    if lang == Lang::Matlab && name.len() > 63 {
        return Err(format!(
            "`{name}` has {} characters: MATLAB names have at most 63",
            name.len()
        ));
    }
    if lang == Lang::C
        && (name.starts_with("__")
            || name.starts_with("_") && name[1..].starts_with(|c: char| c.is_ascii_uppercase()))
    {
        return Err(format!(
            "`{name}` is reserved in C (names beginning with `__` or `_` and a capital letter)"
        ));
    }
    if keywords(lang).split_whitespace().any(|k| k == name) {
        return Err(format!("`{name}` is a reserved word of {language}"));
    }
    if lang != Lang::Text && lang != Lang::Latex && CODE_NAMES.split_whitespace().any(|k| k == name)
    {
        return Err(format!(
            "`{name}` is a name the generated {language} code uses itself (its arguments, \
             helpers and math functions: {CODE_NAMES})"
        ));
    }
    Ok(())
}

/// Names of a program's symbols in generated code. A symbol whose name is reserved (a robot
/// symbol `p`, `end` or `in`) is written with underscores appended until the name is free; the
/// caller never sees it, since inputs are passed by position.
struct Names(HashMap<String, String>);

impl Names {
    fn new(p: &Program) -> Names {
        let order: Vec<&str> = p
            .inputs
            .iter()
            .flat_map(|g| g.symbols.iter().flatten())
            .chain(p.assignments.iter().map(|a| &a.name))
            .map(String::as_str)
            .collect();
        let mut used: HashSet<String> = order.iter().map(|n| n.to_string()).collect();
        let mut map = HashMap::new();
        for n in order {
            if is_reserved(n) && !map.contains_key(n) {
                let mut m = format!("{n}_");
                while used.contains(&m) || is_reserved(&m) {
                    m.push('_');
                }
                used.insert(m.clone());
                map.insert(n.to_string(), m);
            }
        }
        Names(map)
    }

    fn get(&self, name: &str) -> String {
        self.0
            .get(name)
            .cloned()
            .unwrap_or_else(|| name.to_string())
    }
}

/// What comes before the function's body: the preamble (includes, helpers, the parameter record
/// type of C and Rust, the parameter names of Python), the signature and the output's allocation.
fn prologue(p: &Program, lang: Lang) -> String {
    let mut s = String::new();
    let name = &p.name;
    let groups: Vec<&str> = p.inputs.iter().map(|g| g.name.as_str()).collect();
    let ind = "    ";
    // C and Rust: the arguments with their types, `array(name)` for an array, `record(name,
    // type)` for the parameter record
    let typed = |array: &dyn Fn(&str) -> String, record: &dyn Fn(&str, &str) -> String| {
        let args: Vec<String> = p
            .inputs
            .iter()
            .map(|g| match parameter_type(p, lang).filter(|_| g.by_name) {
                Some(t) => record(&g.name, &t),
                None => array(&g.name),
            })
            .collect();
        args.join(", ")
    };
    match lang {
        Lang::Rust => {
            if let Some(t) = parameter_type(p, lang) {
                let _ = writeln!(
                    s,
                    "/// The parameters of `{name}`, by name (fields in the order of the header).\n\
                     #[allow(non_snake_case)]\n#[derive(Clone, Copy, Debug, PartialEq)]\n\
                     pub struct {t} {{"
                );
                for (_, f) in parameter_fields(p) {
                    let _ = writeln!(s, "{ind}pub {f}: f64,");
                }
                s.push_str("}\n\n");
            }
            let _ = writeln!(
                s,
                "#[allow(non_snake_case, unused_variables, unused_parens, clippy::all)]\n\
                 pub fn {name}({}, out: &mut [f64]) {{",
                typed(&|g| format!("{g}: &[f64]"), &|g, t| format!("{g}: &{t}"))
            );
            let _ = writeln!(
                s,
                "{ind}#[allow(dead_code)]\n{ind}fn sgn(x: f64) -> f64 {{\n{ind}{ind}if x > 0.0 {{ 1.0 }} else if x < 0.0 {{ -1.0 }} else {{ 0.0 }}\n{ind}}}"
            );
        }
        Lang::C => {
            s.push_str("#include <math.h>\n\n");
            s.push_str(
                "static inline double rd_sign(double x) { return (x > 0.0) - (x < 0.0); }\n\n",
            );
            if let Some(t) = parameter_type(p, lang) {
                s.push_str("typedef struct {\n");
                for (_, f) in parameter_fields(p) {
                    let _ = writeln!(s, "{ind}double {f};");
                }
                let _ = writeln!(s, "}} {t};\n");
            }
            let _ = writeln!(
                s,
                "void {name}({}, double *out) {{",
                typed(&|g| format!("const double *{g}"), &|g, t| {
                    format!("const {t} *{g}")
                })
            );
        }
        Lang::Python => {
            s.push_str("import numpy as np\n");
            if p.inputs.iter().any(|g| g.by_name) {
                let quoted: Vec<String> = parameter_fields(p)
                    .iter()
                    .map(|(sym, _)| format!("{sym:?}"))
                    .collect();
                let _ = writeln!(
                    s,
                    "\n# the names of the parameters p, in the order of the header\n{} = ({},)",
                    python_names_constant(p),
                    quoted.join(", ")
                );
            }
            s.push_str("\n\n");
            let _ = writeln!(s, "def {name}({}, out=None):", groups.join(", "));
            let _ = writeln!(s, "{ind}if out is None:");
            let _ = writeln!(s, "{ind}{ind}out = np.zeros({})", p.outputs.len());
        }
        Lang::Julia => {
            let _ = writeln!(s, "function {name}!(out, {})", groups.join(", "));
        }
        Lang::Matlab => {
            let _ = writeln!(s, "function out = {name}({})", groups.join(", "));
            let _ = writeln!(s, "{ind}out = zeros({}, 1);", p.outputs.len());
        }
        _ => unreachable!(),
    }
    s
}

fn emit_code(p: &Program, lang: Lang) -> String {
    let mut s = header(p, lang);
    s.push_str(&prologue(p, lang));
    let names = &Names::new(p);
    let base = lang.first_index();
    let ind = "    ";
    let decl = match lang {
        Lang::Rust => "let ",
        Lang::C => "const double ",
        _ => "",
    };
    let end = match lang {
        Lang::Rust | Lang::C | Lang::Matlab => ";",
        _ => "",
    };
    // only the inputs the program reads (-Wall clean C; the header lists every position)
    let read: HashSet<String> = p
        .assignments
        .iter()
        .chain(&p.outputs)
        .flat_map(|a| a.expr.symbols())
        .collect();
    for g in &p.inputs {
        let unread = !g.symbols.iter().flatten().any(|s| read.contains(s));
        if lang == Lang::C && unread {
            let _ = writeln!(s, "{ind}(void){};", g.name);
        }
        for (i, sym) in g.symbols.iter().enumerate() {
            if let Some(sym) = sym.as_ref().filter(|s| read.contains(*s)) {
                let var = names.get(sym);
                let value = match (g.by_name, lang) {
                    (false, _) => lang.index(&g.name, i + base),
                    (true, Lang::C) => format!("{}->{var}", g.name),
                    (true, Lang::Python) => format!("{}[{sym:?}]", g.name),
                    (true, _) => format!("{}.{var}", g.name),
                };
                let _ = writeln!(s, "{ind}{decl}{var} = {value}{end}");
            }
        }
    }
    for a in &p.assignments {
        let _ = writeln!(
            s,
            "{ind}{decl}{} = {}{end}",
            names.get(&a.name),
            code(&a.expr, lang, 0, names)
        );
    }
    for (i, o) in p.outputs.iter().enumerate() {
        let _ = writeln!(
            s,
            "{ind}{} = {}{end}  {}{}",
            lang.index("out", i + base),
            code(&o.expr, lang, 0, names),
            lang.comment(),
            o.name
        );
    }
    match lang {
        Lang::Rust | Lang::C => s.push_str("}\n"),
        Lang::Python => {
            let _ = writeln!(s, "{ind}return out");
        }
        Lang::Julia => {
            let _ = writeln!(s, "{ind}return out\nend");
        }
        Lang::Matlab => s.push_str("end\n"),
        _ => {}
    }
    s
}

#[cfg(test)]
mod tests {
    use super::Lang;

    #[test]
    fn every_language_is_read_back_from_its_name() {
        for l in Lang::ALL {
            assert_eq!(Lang::from_name(l.name()), Some(l), "{l:?}");
            assert!(!l.describe().is_empty());
        }
        let mut names: Vec<&str> = Lang::ALL.iter().map(|l| l.name()).collect();
        names.dedup();
        assert_eq!(names.len(), 7);
        assert_eq!(Lang::from_name("fortran"), None);
    }
}
