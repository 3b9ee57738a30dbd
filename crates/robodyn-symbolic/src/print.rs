//! Plain-text printing of expressions (`d3^2*(M3 + M4) - MX8/d3`), with minimal parentheses.

use crate::expr::{grow, Expr, Node};
use num_rational::Rational64;
use num_traits::{One, Signed};
use std::fmt;

const PREC_SUM: u8 = 0;
const PREC_PRODUCT: u8 = 1;
const PREC_POWER: u8 = 2;

impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_expr(f, self, PREC_SUM, false)
    }
}

/// [`Expr::decimal`]: the expression printed with decimal numbers where they are exact.
pub struct Decimal<'a>(&'a Expr);

impl fmt::Display for Decimal<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_expr(f, self.0, PREC_SUM, true)
    }
}

impl Expr {
    /// The expression as a file writes it: like `Display`, except that a rational number with
    /// a finite decimal expansion that reads back to the same rational prints as that decimal
    /// (`0.705`, `-9.81`, not `141/200`, `-981/100`), and so does the coefficient of a product
    /// (`0.705*d3`) unless it is `1/n` (`pi/2`, `M3/4`). Other rationals keep their exact
    /// form (`1/3`, `2*pi/3`); floats print as their shortest round-trip digits. What prints
    /// reads back (through [`Expr::parse`]) to the same expression.
    pub fn decimal(&self) -> Decimal<'_> {
        Decimal(self)
    }
}

/// The exact decimal text of `r` when it has one that [`Expr::num`] reads back to `r` itself
/// (a denominator 2^a 5^b, at most 9 decimals: what `Expr::num` recognizes as exact).
pub(crate) fn exact_decimal(r: &Rational64) -> Option<String> {
    if r.is_integer() {
        return Some(r.numer().to_string());
    }
    let mut d = *r.denom();
    let (mut twos, mut fives) = (0u32, 0u32);
    while d % 2 == 0 {
        d /= 2;
        twos += 1;
    }
    while d % 5 == 0 {
        d /= 5;
        fives += 1;
    }
    let k = twos.max(fives);
    if d != 1 || k > 9 {
        return None;
    }
    let scaled = r.numer().checked_mul(10i64.pow(k) / r.denom())?;
    let digits = scaled.unsigned_abs().to_string();
    let k = k as usize;
    let padded = format!("{digits:0>width$}", width = k + 1);
    let (int, frac) = padded.split_at(padded.len() - k);
    let sign = if scaled < 0 { "-" } else { "" };
    let text = format!("{sign}{int}.{frac}");
    let back = text.parse::<f64>().ok().map(Expr::num)?;
    (back.as_rational() == Some(*r)).then_some(text)
}

fn write_rational(f: &mut fmt::Formatter<'_>, r: &Rational64, prec: u8, dec: bool) -> fmt::Result {
    if dec && !r.is_integer() {
        if let Some(text) = exact_decimal(r) {
            return if r.is_negative() && prec > PREC_SUM {
                write!(f, "({text})")
            } else {
                write!(f, "{text}")
            };
        }
    }
    let needs = (r.is_negative() && prec > PREC_SUM) || (!r.is_integer() && prec > PREC_PRODUCT);
    if needs {
        write!(f, "(")?;
    }
    if r.is_integer() {
        write!(f, "{}", r.numer())?;
    } else {
        write!(f, "{}/{}", r.numer(), r.denom())?;
    }
    if needs {
        write!(f, ")")?;
    }
    Ok(())
}

fn write_expr(f: &mut fmt::Formatter<'_>, e: &Expr, prec: u8, dec: bool) -> fmt::Result {
    grow(|| write_node(f, e, prec, dec))
}

fn write_node(f: &mut fmt::Formatter<'_>, e: &Expr, prec: u8, dec: bool) -> fmt::Result {
    match e.node() {
        Node::Rational(r) => write_rational(f, r, prec, dec),
        // Debug format: shortest digits that read back to the same float, always with a `.` or
        // an exponent, so that the parser reads it back as a float (not an exact integer)
        Node::Float(x) => {
            if *x < 0.0 && prec > PREC_SUM {
                write!(f, "({x:?})")
            } else {
                write!(f, "{x:?}")
            }
        }
        Node::Pi => write!(f, "pi"),
        Node::Symbol(s) => write!(f, "{s}"),
        Node::Add(terms) => {
            if prec > PREC_SUM {
                write!(f, "(")?;
            }
            for (i, t) in terms.iter().enumerate() {
                let negative = term_is_negative(t);
                if i == 0 {
                    write_expr(f, t, PREC_SUM, dec)?;
                    // a leading product with a negative coefficient prints its own minus sign
                } else if negative {
                    write!(f, " - ")?;
                    let neg = -t.clone();
                    // a negated sum keeps its parentheses: a - (b + c)
                    let prec = if matches!(neg.node(), Node::Add(_)) {
                        PREC_PRODUCT
                    } else {
                        PREC_SUM
                    };
                    write_expr(f, &neg, prec, dec)?;
                } else {
                    write!(f, " + ")?;
                    write_expr(f, t, PREC_SUM, dec)?;
                }
            }
            if prec > PREC_SUM {
                write!(f, ")")?;
            }
            Ok(())
        }
        Node::Mul(_) | Node::Pow(..) => write_product(f, e, prec, dec),
        Node::Func(func, a) => {
            write!(f, "{}(", func.name())?;
            write_expr(f, a, PREC_SUM, dec)?;
            write!(f, ")")
        }
        Node::Atan2(y, x) => {
            write!(f, "atan2(")?;
            write_expr(f, y, PREC_SUM, dec)?;
            write!(f, ", ")?;
            write_expr(f, x, PREC_SUM, dec)?;
            write!(f, ")")
        }
    }
}

/// True when a term prints with a leading minus sign.
pub(crate) fn term_is_negative(t: &Expr) -> bool {
    match t.node() {
        Node::Rational(r) => r.is_negative(),
        Node::Float(x) => *x < 0.0,
        Node::Mul(v) => match v[0].node() {
            Node::Rational(r) => r.is_negative(),
            Node::Float(x) => *x < 0.0,
            _ => false,
        },
        _ => false,
    }
}

/// Split a product into (numeric coefficient, numerator factors, denominator factors).
pub(crate) fn product_parts(e: &Expr) -> (Option<Expr>, Vec<Expr>, Vec<Expr>) {
    let factors: Vec<Expr> = match e.node() {
        Node::Mul(v) => v.clone(),
        _ => vec![e.clone()],
    };
    let mut coef = None;
    let mut num = Vec::new();
    let mut den = Vec::new();
    for fa in factors {
        match fa.node() {
            Node::Rational(_) | Node::Float(_) => coef = Some(fa.clone()),
            Node::Pow(b, n) if *n < 0 => den.push(b.powi(-n)),
            _ => num.push(fa.clone()),
        }
    }
    (coef, num, den)
}

fn write_product(f: &mut fmt::Formatter<'_>, e: &Expr, prec: u8, dec: bool) -> fmt::Result {
    if let Node::Pow(b, n) = e.node() {
        if *n > 0 {
            // a power as the base of a power keeps its parentheses: (x^40)^2
            let wrap = prec > PREC_POWER;
            if wrap {
                write!(f, "(")?;
            }
            write_expr(f, b, PREC_POWER + 1, dec)?;
            write!(f, "^{n}")?;
            if wrap {
                write!(f, ")")?;
            }
            return Ok(());
        }
    }
    let (coef, num, den) = product_parts(e);
    let mut num_coef: Option<Expr> = None;
    let mut den_coef: Option<i64> = None;
    let mut negative = false;
    if let Some(c) = coef {
        match c.node() {
            Node::Rational(r) => {
                negative = r.is_negative();
                let a = r.abs();
                // decimal mode: 0.705*d3, but pi/2 stays pi/2
                let decimal = (dec && !a.numer().is_one())
                    .then(|| exact_decimal(&a))
                    .flatten();
                if decimal.is_some() {
                    num_coef = Some(Expr::rational(a));
                } else if !a.numer().is_one() || num.is_empty() {
                    num_coef = Some(Expr::int(*a.numer()));
                }
                if !a.denom().is_one() && decimal.is_none() {
                    den_coef = Some(*a.denom());
                }
            }
            Node::Float(x) => {
                negative = *x < 0.0;
                num_coef = Some(Expr::num(x.abs()));
            }
            _ => unreachable!(),
        }
    }
    let wrap = prec > PREC_PRODUCT || (negative && prec > PREC_SUM + 1);
    if wrap {
        write!(f, "(")?;
    }
    if negative {
        write!(f, "-")?;
    }
    let mut first = true;
    if let Some(c) = &num_coef {
        write_expr(f, c, PREC_PRODUCT, dec)?;
        first = false;
    }
    for x in &num {
        if !first {
            write!(f, "*")?;
        }
        write_expr(f, x, PREC_PRODUCT + 1, dec)?;
        first = false;
    }
    if first {
        write!(f, "1")?;
    }
    let den_count = den.len() + usize::from(den_coef.is_some());
    if den_count > 0 {
        write!(f, "/")?;
        if den_count > 1 {
            write!(f, "(")?;
        }
        let mut first = true;
        if let Some(d) = den_coef {
            write!(f, "{d}")?;
            first = false;
        }
        for x in &den {
            if !first {
                write!(f, "*")?;
            }
            write_expr(f, x, PREC_PRODUCT + 1, dec)?;
            first = false;
        }
        if den_count > 1 {
            write!(f, ")")?;
        }
    }
    if wrap {
        write!(f, ")")?;
    }
    Ok(())
}
