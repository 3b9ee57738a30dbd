//! Parser for the expressions found in robot files: numbers, symbols, `pi`, `+ - * / ^ **`,
//! parentheses, the functions `sin cos tan sqrt abs sign` and `atan2(y, x)`.
//!
//! Nesting (parentheses, function calls, signs, exponents) is limited to [`MAX_DEPTH`] levels:
//! the parser is recursive descent, and a file must not be able to exhaust its stack.

use crate::expr::{Expr, Func, Node};

/// Deepest nesting of parentheses, function calls, unary signs and exponents accepted.
pub const MAX_DEPTH: usize = 200;

/// Largest exponent (in absolute value) written in an expression (`x^64`).
pub const MAX_EXPONENT: i32 = crate::expr::MAX_POWER;

/// A parse error with the byte offset (0-based) of the offending character in the input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("column {}: {message}", .offset + 1)]
pub struct ParseError {
    /// Byte offset of the offending character.
    pub offset: usize,
    /// What is wrong.
    pub message: String,
}

impl Expr {
    /// Parse an expression such as `-pi/2`, `d12*cos(g12)`, `0.45`, `RL4`.
    pub fn parse(text: &str) -> Result<Expr, ParseError> {
        let mut p = Parser {
            s: text.as_bytes(),
            pos: 0,
            depth: 0,
        };
        p.skip_ws();
        if p.pos >= p.s.len() {
            return Err(p.err("empty expression"));
        }
        let e = p.sum()?;
        p.skip_ws();
        if p.pos < p.s.len() {
            return Err(p.err(&format!("unexpected `{}`", p.s[p.pos] as char)));
        }
        if has_non_finite(&e) {
            return Err(ParseError {
                offset: 0,
                message: "the expression is infinite or undefined (a division by zero, \
                          tan(pi/2)...)"
                    .into(),
            });
        }
        Ok(e)
    }
}

/// Whether a number of the expression is infinite or NaN.
fn has_non_finite(e: &Expr) -> bool {
    crate::expr::grow(|| match e.node() {
        Node::Float(x) => !x.is_finite(),
        Node::Add(v) | Node::Mul(v) => v.iter().any(has_non_finite),
        Node::Pow(b, _) | Node::Func(_, b) => has_non_finite(b),
        Node::Atan2(y, x) => has_non_finite(y) || has_non_finite(x),
        _ => false,
    })
}

struct Parser<'a> {
    s: &'a [u8],
    pos: usize,
    /// Current nesting depth (see [`MAX_DEPTH`]).
    depth: usize,
}

impl Parser<'_> {
    fn err(&self, m: &str) -> ParseError {
        ParseError {
            offset: self.pos,
            message: m.to_string(),
        }
    }

    fn skip_ws(&mut self) {
        while self.pos < self.s.len() && self.s[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_ws();
        self.s.get(self.pos).copied()
    }

    fn sum(&mut self) -> Result<Expr, ParseError> {
        let mut acc = self.product()?;
        while let Some(c) = self.peek() {
            match c {
                b'+' => {
                    self.pos += 1;
                    acc += self.product()?;
                }
                b'-' => {
                    self.pos += 1;
                    acc -= self.product()?;
                }
                _ => break,
            }
        }
        Ok(acc)
    }

    fn product(&mut self) -> Result<Expr, ParseError> {
        let mut acc = self.unary()?;
        loop {
            match self.peek() {
                Some(b'*') if self.s.get(self.pos + 1) != Some(&b'*') => {
                    self.pos += 1;
                    acc *= self.unary()?;
                }
                Some(b'/') => {
                    self.pos += 1;
                    let at = self.pos;
                    let d = self.unary()?;
                    if d.is_zero() {
                        return Err(ParseError {
                            offset: at,
                            message: "division by zero".into(),
                        });
                    }
                    acc /= d;
                }
                _ => break,
            }
        }
        Ok(acc)
    }

    /// Every recursion of the grammar goes through here: the nesting depth is counted once.
    fn unary(&mut self) -> Result<Expr, ParseError> {
        if self.depth >= MAX_DEPTH {
            return Err(self.err(&format!(
                "the expression is nested more than {MAX_DEPTH} levels deep (parentheses, \
                 functions, signs or exponents)"
            )));
        }
        self.depth += 1;
        let e = self.unary_inner();
        self.depth -= 1;
        e
    }

    fn unary_inner(&mut self) -> Result<Expr, ParseError> {
        match self.peek() {
            Some(b'-') => {
                self.pos += 1;
                Ok(-self.unary()?)
            }
            Some(b'+') => {
                self.pos += 1;
                self.unary()
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> Result<Expr, ParseError> {
        let base = self.atom()?;
        let is_pow = match self.peek() {
            Some(b'^') => {
                self.pos += 1;
                true
            }
            Some(b'*') if self.s.get(self.pos + 1) == Some(&b'*') => {
                self.pos += 2;
                true
            }
            _ => false,
        };
        if !is_pow {
            return Ok(base);
        }
        let at = self.pos;
        let exp = self.unary()?;
        match exp.as_rational() {
            Some(r) if r.is_integer() && r.numer().abs() <= MAX_EXPONENT as i64 => {
                Ok(base.powi(*r.numer() as i32))
            }
            Some(r) if *r.denom() == 2 && *r.numer() == 1 => Ok(base.sqrt()),
            _ => Err(ParseError {
                offset: at,
                message: format!(
                    "only integer exponents from -{MAX_EXPONENT} to {MAX_EXPONENT} (or 1/2) are \
                     supported"
                ),
            }),
        }
    }

    fn atom(&mut self) -> Result<Expr, ParseError> {
        let c = match self.peek() {
            Some(c) => c,
            None => return Err(self.err("unexpected end of expression")),
        };
        if c == b'(' {
            self.pos += 1;
            let e = self.sum()?;
            if self.peek() != Some(b')') {
                return Err(self.err("expected `)`"));
            }
            self.pos += 1;
            return Ok(e);
        }
        if c.is_ascii_digit() || c == b'.' {
            return self.number();
        }
        if c.is_ascii_alphabetic() || c == b'_' {
            let start = self.pos;
            while self.pos < self.s.len()
                && (self.s[self.pos].is_ascii_alphanumeric() || self.s[self.pos] == b'_')
            {
                self.pos += 1;
            }
            let name = std::str::from_utf8(&self.s[start..self.pos]).unwrap_or("");
            if self.peek() == Some(b'(') {
                if name.eq_ignore_ascii_case("atan2") {
                    self.pos += 1;
                    let y = self.sum()?;
                    if self.peek() != Some(b',') {
                        return Err(self.err("expected `,` between the arguments of atan2(y, x)"));
                    }
                    self.pos += 1;
                    let x = self.sum()?;
                    if self.peek() != Some(b')') {
                        return Err(self.err("expected `)`"));
                    }
                    self.pos += 1;
                    return Ok(Expr::atan2(y, x));
                }
                let f = Func::from_name(name).ok_or(ParseError {
                    offset: start,
                    message: format!("unknown function `{name}`"),
                })?;
                self.pos += 1;
                let a = self.sum()?;
                if self.peek() != Some(b')') {
                    return Err(self.err("expected `)`"));
                }
                self.pos += 1;
                return Ok(Expr::func(f, a));
            }
            return Ok(match name {
                "pi" | "Pi" | "PI" => Expr::pi(),
                _ => Expr::symbol(name),
            });
        }
        Err(self.err(&format!("unexpected `{}`", c as char)))
    }

    fn number(&mut self) -> Result<Expr, ParseError> {
        let start = self.pos;
        let s = self.s;
        let mut i = self.pos;
        while i < s.len() && (s[i].is_ascii_digit() || s[i] == b'.') {
            i += 1;
        }
        if i < s.len() && (s[i] == b'e' || s[i] == b'E') {
            let mut k = i + 1;
            if k < s.len() && (s[k] == b'+' || s[k] == b'-') {
                k += 1;
            }
            if k < s.len() && s[k].is_ascii_digit() {
                while k < s.len() && s[k].is_ascii_digit() {
                    k += 1;
                }
                i = k;
            }
        }
        let text = std::str::from_utf8(&s[start..i]).unwrap_or("");
        self.pos = i;
        // an integer literal is exact (`1234440111544321` is not rounded to a float)
        if text.bytes().all(|c| c.is_ascii_digit()) {
            if let Ok(n) = text.parse::<i64>() {
                return Ok(Expr::int(n));
            }
        }
        match text.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(Expr::num(x)),
            Ok(_) => Err(ParseError {
                offset: start,
                message: format!("number `{text}` is not a finite number (out of range)"),
            }),
            Err(_) => Err(ParseError {
                offset: start,
                message: format!("bad number `{text}`"),
            }),
        }
    }
}
