//! Text, LaTeX and JSON writers of a base-parameter [`Summary`].

use crate::algorithms::base_parameters::summary::{Summary, LEGEND};
use crate::report::number::{significant, Sig};
use serde_json::json;

/// Plain-text report: title, comparison block (when the methods differ), the table like
/// Table 10.2 and its legend, the lists, the grouping equations, the values, the notes.
pub fn text(r: &Summary) -> String {
    let mut s = format!(
        "{}: {} base parameters ({} method)\n\n",
        r.robot,
        r.count(),
        r.method
    );
    if let Some(b) = r.comparison.as_ref().and_then(|c| c.block()) {
        s.push_str(&b);
    }
    let t = r.table();
    let w: Vec<usize> = (0..t[0].len())
        .map(|c| t.iter().map(|row| row[c].len()).max().unwrap_or(1))
        .collect();
    for row in &t {
        let line: Vec<String> = row
            .iter()
            .zip(&w)
            .map(|(x, &n)| format!("{x:<n$}"))
            .collect();
        s.push_str(line.join("  ").trim_end());
        s.push('\n');
    }
    s.push_str(&format!("Legend: {LEGEND}.\n"));
    s.push_str(&format!(
        "\nNo effect ({}): {}\n",
        r.no_effect.len(),
        r.no_effect.join(", ")
    ));
    s.push_str(&format!(
        "Grouped ({}): {}\n\nGrouping equations:\n",
        r.grouped.len(),
        r.grouped.join(", ")
    ));
    for b in r.base.iter().filter(|b| b.regrouped) {
        s.push_str(&format!("  {} = {}\n", b.name, b.equation));
    }
    let width = r.base.iter().map(|b| b.name.len()).max().unwrap_or(1);
    if r.base.iter().any(|b| b.value.is_some()) {
        s.push_str("\nValues (rounded to 12 significant digits):\n");
        for b in &r.base {
            match b.value {
                Some(v) => s.push_str(&format!(
                    "  {:<width$} = {}\n",
                    b.name,
                    Sig(v, VALUE_DIGITS)
                )),
                None => s.push_str(&format!(
                    "  {:<width$} = (parameters without value)\n",
                    b.name
                )),
            }
        }
    } else {
        s.push_str("\nValues: none (the file gives no numeric values to these parameters)\n");
    }
    for n in &r.notes {
        s.push_str(&format!("\nNote: {n}"));
    }
    if !r.notes.is_empty() {
        s.push('\n');
    }
    s
}

/// Significant digits of a value for display: 12, the rounding of the sums that make it
/// (10.899999999999999 -> 10.9) in the report form of [`crate::report::number`]. JSON keeps the
/// full double.
const VALUE_DIGITS: usize = 12;

/// LaTeX fragment (needs amsmath): the table (tabular, math cells), its legend, the grouping
/// equations (align*, long sums broken between terms) and the values.
pub fn latex(r: &Summary) -> String {
    let t = r.table();
    let mut s = format!(
        "% {}: {} base parameters ({} method)\n",
        r.robot,
        r.count(),
        r.method
    );
    if let Some(b) = r.comparison.as_ref().and_then(|c| c.block()) {
        for l in b.lines() {
            s.push_str(&format!("% {l}\n"));
        }
    }
    // Table 10.2's twelve columns fit the text width in \scriptsize; more (friction) in \tiny
    let size = if t[0].len() > 12 {
        "tiny"
    } else {
        "scriptsize"
    };
    s.push_str(&format!(
        "{{\\{size}\\setlength{{\\tabcolsep}}{{2pt}}\n\\begin{{tabular}}{{{}}}\n",
        "c".repeat(t[0].len())
    ));
    for (k, row) in t.iter().enumerate() {
        let cells: Vec<String> = if k == 0 {
            row.iter().map(|x| latex_header(x)).collect()
        } else {
            row.iter().map(|x| latex_cell(x)).collect()
        };
        s.push_str(&format!("{} \\\\\n", cells.join(" & ")));
        if k == 0 {
            s.push_str("\\hline\n");
        }
    }
    s.push_str("\\end{tabular}}\n\n");
    s.push_str(&format!(
        "\\noindent{{\\small {}.}}\n",
        latex_text(&format!("Legend: {LEGEND}"))
    ));
    if r.base.iter().any(|b| b.regrouped) {
        s.push_str("\\begin{align*}\n");
        for b in r.base.iter().filter(|b| b.regrouped) {
            let lines = break_sum(&b.equation, 48);
            for (i, l) in lines.iter().enumerate() {
                let lhs = if i == 0 {
                    format!("{} &= ", latex_name(&b.name))
                } else {
                    "&\\quad ".to_string()
                };
                s.push_str(&format!("{lhs}{} \\\\\n", latex_equation(l)));
            }
        }
        s.push_str("\\end{align*}\n");
    }
    let values: Vec<String> = r
        .base
        .iter()
        .filter_map(|b| {
            b.value.map(|v| {
                format!(
                    "${}$ & ${}$",
                    latex_name(&b.name),
                    latex_number(&significant(v, VALUE_DIGITS))
                )
            })
        })
        .collect();
    if !values.is_empty() {
        // two name-value pairs per row
        s.push_str("\n\\noindent Values:\\\\\n{\\small\\begin{tabular}{rlrl}\n");
        for chunk in values.chunks(2) {
            s.push_str(&format!("{} \\\\\n", chunk.join(" & ")));
        }
        s.push_str("\\end{tabular}}\n");
    }
    // visible in the document (the tolerance applied to float terms is one of them)
    for n in &r.notes {
        let t = latex_text(n)
            .replace('^', "\\textasciicircum{}")
            .replace('~', "\\textasciitilde{}");
        s.push_str(&format!("\n\\noindent{{\\small Note: {t}}}\\par\n"));
    }
    s
}

/// JSON: `robot`, `method`, `count`, `base` [{name, standard, equation, value}], `no_effect`,
/// `grouped`, `legend`, `notes`, and with both methods `comparison` {arbiter, same,
/// symbolic_count, numeric_count, symbolic_only, numeric_only}.
pub fn json(r: &Summary) -> serde_json::Value {
    let mut o = json!({
        "robot": r.robot,
        "method": r.method,
        "count": r.count(),
        "base": r.base.iter().map(|b| json!({
            "name": b.name,
            "standard": r.names.name(b.index),
            "equation": b.equation,
            "value": b.value,
        })).collect::<Vec<_>>(),
        "no_effect": r.no_effect,
        "grouped": r.grouped,
        "legend": LEGEND,
        "notes": r.notes,
    });
    if let Some(c) = &r.comparison {
        o["comparison"] = json!({
            "arbiter": "numeric",
            "same": c.same(),
            "symbolic_count": c.symbolic_count,
            "numeric_count": c.numeric_count,
            "symbolic_only": c.symbolic_only,
            "numeric_only": c.numeric_only,
        });
    }
    o
}

/// Split a text sum at its top-level ` + ` / ` - ` into lines of at most `width` characters
/// (a single term longer than that stays whole); continuation lines start with their sign.
fn break_sum(e: &str, width: usize) -> Vec<String> {
    let mut terms: Vec<String> = Vec::new();
    let mut depth = 0i32;
    let mut cur = String::new();
    let chars: Vec<char> = e.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            _ => {}
        }
        if depth == 0
            && c == ' '
            && i + 2 < chars.len()
            && (chars[i + 1] == '+' || chars[i + 1] == '-')
            && chars[i + 2] == ' '
            && !cur.is_empty()
        {
            terms.push(std::mem::take(&mut cur));
            cur.push(chars[i + 1]);
            cur.push(' ');
            i += 3;
            continue;
        }
        cur.push(c);
        i += 1;
    }
    if !cur.is_empty() {
        terms.push(cur);
    }
    let mut lines: Vec<String> = Vec::new();
    for t in terms {
        match lines.last_mut() {
            Some(l) if l.len() + 1 + t.len() <= width => {
                l.push(' ');
                l.push_str(&t);
            }
            _ => lines.push(t),
        }
    }
    lines
}

/// A header cell: `XXj` -> `$XX_j$`, `j` -> `$j$`.
fn latex_header(x: &str) -> String {
    match x.strip_suffix('j') {
        Some(p) if !p.is_empty() => {
            if p == "IA" {
                "$I_{aj}$".into()
            } else {
                format!("${p}_j$")
            }
        }
        _ => format!("${x}$"),
    }
}

/// A table cell: names in math mode (`$XXR_{2}$`), `0` and `-` as they are.
fn latex_cell(x: &str) -> String {
    match x {
        "0" => "0".into(),
        "-" => "--".into(),
        "j" => "$j$".into(),
        _ => format!("${}$", latex_name(x)),
    }
}

/// Escape LaTeX specials in running text.
fn latex_text(s: &str) -> String {
    s.replace('\\', "\\textbackslash{}")
        .replace('_', "\\_")
        .replace('%', "\\%")
        .replace('&', "\\&")
        .replace('#', "\\#")
        .replace('$', "\\$")
}

/// A number in math mode: `1.5e-7` -> `1.5 \cdot 10^{-7}`.
fn latex_number(x: &str) -> String {
    match x.split_once('e') {
        Some((m, e)) if m.parse::<f64>().is_ok() && e.parse::<i32>().is_ok() => {
            format!("{m} \\cdot 10^{{{e}}}")
        }
        _ => x.to_string(),
    }
}

/// `XXR2` -> `XXR_{2}`, `IA4` -> `I_{a4}`, `d3` -> `d_{3}`, `RL4` -> `RL_{4}`, `M11_` ->
/// `M11\_` (names robodyn made unique), `th` -> `th`.
fn latex_name(n: &str) -> String {
    if n.ends_with('_') || n.contains('_') {
        return format!("\\mathit{{{}}}", n.replace('_', "\\_"));
    }
    match n.find(|c: char| c.is_ascii_digit()) {
        Some(k) if k > 0 && n[k..].chars().all(|c| c.is_ascii_digit()) => {
            let (a, d) = n.split_at(k);
            if a == "IA" {
                format!("I_{{a{d}}}")
            } else {
                format!("{a}_{{{d}}}")
            }
        }
        _ if n == "pi" => "\\pi".into(),
        _ => n.to_string(),
    }
}

/// Text equation to LaTeX: names subscripted, `*` dropped, `^k` braced, `/` kept, numbers
/// with exponents as powers of ten.
fn latex_equation(e: &str) -> String {
    let mut out = String::new();
    let mut word = String::new();
    let flush = |w: &mut String, out: &mut String| {
        if !w.is_empty() {
            if w.starts_with(|c: char| c.is_ascii_digit()) {
                out.push_str(&latex_number(w));
            } else {
                out.push_str(&latex_name(w));
            }
            w.clear();
        }
    };
    let chars: Vec<char> = e.chars().collect();
    for (i, &c) in chars.iter().enumerate() {
        let exponent_sign = (c == '-' || c == '+')
            && word.starts_with(|d: char| d.is_ascii_digit())
            && word.ends_with('e')
            && chars.get(i + 1).is_some_and(|d| d.is_ascii_digit());
        if c.is_ascii_alphanumeric() || c == '_' || c == '.' || exponent_sign {
            word.push(c);
        } else {
            flush(&mut word, &mut out);
            match c {
                '*' => out.push(' '),
                '/' => out.push_str(" / "),
                '^' => out.push('^'),
                _ => out.push(c),
            }
        }
    }
    flush(&mut word, &mut out);
    // braces around exponents: ^2 -> ^{2}
    let mut res = String::new();
    let mut it = out.chars().peekable();
    while let Some(c) = it.next() {
        res.push(c);
        if c == '^' && it.peek() != Some(&'{') {
            let mut exp = String::new();
            while let Some(&d) = it.peek() {
                if d.is_ascii_digit() || (exp.is_empty() && d == '-') {
                    exp.push(d);
                    it.next();
                } else {
                    break;
                }
            }
            res.push_str(&format!("{{{exp}}}"));
        }
    }
    res
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_break_between_top_level_terms() {
        let l = break_sum("XX2 - YY2 + d3^2*(M3 + M4 + M5 + M6) - 0.5*M7", 20);
        assert_eq!(l, ["XX2 - YY2", "+ d3^2*(M3 + M4 + M5 + M6)", "- 0.5*M7"]);
    }

    #[test]
    fn latex_of_names_and_numbers() {
        assert_eq!(
            latex_equation("d3^2*M4 + 1.5e-7*IA2"),
            "d_{3}^{2} M_{4} + 1.5 \\cdot 10^{-7} I_{a2}"
        );
        assert_eq!(latex_name("M11_"), "\\mathit{M11\\_}");
    }
}
