use crate::Expr;

fn p(s: &str) -> Expr {
    Expr::parse(s).unwrap()
}

#[test]
fn parses_and_prints() {
    assert_eq!(p("-pi/2").to_string(), "-pi/2");
    assert_eq!(p("d12*cos(g12)").to_string(), "d12*cos(g12)");
    assert_eq!(p("2*x + 3*x").to_string(), "5*x");
    assert_eq!(p("x - x").to_string(), "0");
    assert_eq!(p("MX8/d3").to_string(), "MX8/d3");
    assert_eq!(p("d3^2*(M3 + M4)").to_string(), "d3^2*(M3 + M4)");
    assert_eq!(p("XX2 - YY2").to_string(), "XX2 - YY2");
    assert_eq!(p("-d8").to_string(), "-d8");
    assert_eq!(p("0.45").to_string(), "9/20");
}

#[test]
fn exact_trigonometry_of_half_pi_multiples() {
    assert!(p("cos(pi/2)").is_zero());
    assert!(p("sin(pi/2)").is_one());
    assert_eq!(p("sin(-pi/2)").as_f64(), Some(-1.0));
    assert_eq!(p("cos(3*pi)").as_f64(), Some(-1.0));
    assert_eq!(p("sin(-x)").to_string(), "-sin(x)");
    assert_eq!(p("cos(-x)").to_string(), "cos(x)");
}

#[test]
fn evaluates_with_symbols() {
    let e = p("d3*cos(g) + RL4^2");
    let v = e
        .eval(&|s| match s {
            "d3" => Some(2.0),
            "g" => Some(0.0),
            "RL4" => Some(3.0),
            _ => None,
        })
        .unwrap();
    assert_eq!(v, 11.0);
    assert!(p("a + b").eval(&|s| (s == "a").then_some(1.0)).is_err());
}

#[test]
fn parse_errors_carry_offsets() {
    let e = Expr::parse("d3 + * 2").unwrap_err();
    assert_eq!(e.offset, 5);
    assert!(Expr::parse("foo(2)").is_err());
    assert!(Expr::parse("(a + b").is_err());
    assert!(Expr::parse("").is_err());
    assert!(Expr::parse("1/0").is_err());
}

#[test]
fn expand_distributes() {
    assert_eq!(p("(a + b)*(a - b)").expand().to_string(), "a^2 - b^2");
}

#[test]
fn trig_of_shifted_arguments_folds() {
    assert_eq!(p("sin(q + pi/2)"), p("cos(q)"));
    assert_eq!(p("cos(q + pi/2)"), p("-sin(q)"));
    assert_eq!(p("sin(q - pi/2)"), p("-cos(q)"));
    assert_eq!(p("cos(q + pi)"), p("-cos(q)"));
    assert_eq!(p("sin(q + 3*pi/2)"), p("-cos(q)"));
    assert_eq!(p("cos(q + 0.3)").to_string(), "cos(3/10 + q)");
    for x in [-2.0f64, 0.4, 1.7] {
        for (a, b) in [
            ("sin(q + pi/2)", x.cos()),
            ("cos(q - pi/2)", x.sin()),
            ("cos(q + pi)", -x.cos()),
        ] {
            let v = p(a).eval(&|_| Some(x)).unwrap();
            assert!((v - b).abs() < 1e-15, "{a} at {x}");
        }
    }
}

#[test]
fn powers_of_sums_expand_term_by_term() {
    // a product of equal sums folds back into their power: expansion multiplies out instead
    assert_eq!(p("(a+b)^3").expand(), p("a^3 + 3*a^2*b + 3*a*b^2 + b^3"));
    let e = p("((a+b)*(c-d))^2").expand();
    let v = |e: &Expr| {
        e.eval(&|s| Some(s.len() as f64 + s.as_bytes()[0] as f64 / 50.0))
            .unwrap()
    };
    assert!((v(&e) - v(&p("((a+b)*(c-d))^2"))).abs() < 1e-12);
    assert!(
        !e.to_string().contains('^') || !e.to_string().contains('('),
        "{e}"
    );
}

#[test]
fn canonical_forms_print_and_read_back() {
    // fuzzer findings: a negated sum inside a sum, a float that reads back as a rational, large
    // integers, merged powers beyond the parser's exponent bound
    for (text, printed) in [
        ("s - (a - b + c)", "-a + b - c + s"),
        ("2*(a+b) - (a+b)", "-a - b + 2*(a + b)"),
        ("1234440111544321*x", "1234440111544321*x"),
        ("22*222*B2*222*222222222222", "240943999999759056*B2"),
        ("x^55*x^55", "x^55*x^55"),
        ("(x^40)^2", "(x^40)^2"),
    ] {
        let e = p(text);
        assert_eq!(e.to_string(), printed, "{text}");
        assert_eq!(p(printed).to_string(), printed, "{text}");
    }
    // a coefficient overflowing i64 becomes a float, printed so that it reads back as one
    let e = p("22*222*B2*222*222222222222*1000");
    assert!(e.to_string().contains("e20*B2"), "{e}");
    assert_eq!(p(&e.to_string()).to_string(), e.to_string());
    assert!(Expr::parse("0^-6").is_err());
    assert!(Expr::parse("tan(pi/2)").is_err());
    assert!(Expr::parse("1e999").is_err());
}

#[test]
fn like_terms_collect_beyond_the_linear_search() {
    // 20 distinct terms, then each again: the index built at 16 parts must hold all of them
    // (a fuzzer finding: `- a2 - a2` printed instead of `- 2*a2`)
    let names: Vec<String> = (0..20).map(|i| format!("s{i}")).collect();
    let terms = names.iter().chain(&names).map(Expr::symbol);
    let e = Expr::sum(terms);
    let expected = Expr::sum(names.iter().map(|n| Expr::int(2) * Expr::symbol(n)));
    assert_eq!(e, expected, "{e}");
    assert_eq!(e.to_string().matches("s7").count(), 1, "{e}");
    let f = Expr::product(names.iter().chain(&names).map(Expr::symbol));
    assert_eq!(f.to_string().matches("s19").count(), 1, "{f}");
    assert!(f.to_string().contains("s19^2"), "{f}");
    // and the fuzzer's input prints stably
    let text = "t/s/i+sr-xH-aqs-Xa-q-ss-p-H-xsa-r-X/s/i+q-x+i+q-xq-q+ax-a2+ax-a2";
    let once = p(text).to_string();
    assert_eq!(p(&once).to_string(), once);
    assert!(once.contains("2*a2"), "{once}");
}

#[test]
fn expansion_is_bounded() {
    // a fuzzer finding: a 62-character expression whose expansion took 33 s and 370 MB
    let e = p("(a+b+c+d+e+f+g+h)^54*(x+y)");
    let x = e.expand();
    // kept as a power (too many terms), still the same value
    let env = |s: &str| Some(0.01 * s.as_bytes()[0] as f64);
    let (v, w) = (e.eval(&env).unwrap(), x.eval(&env).unwrap());
    assert!((v - w).abs() <= 1e-12 * v.abs(), "{v} {w}");
    assert!(x.to_string().contains("^54"), "{x}");
    // small ones still multiply out
    assert_eq!(p("(a+b)^2").expand(), p("a^2 + 2*a*b + b^2"));
}

#[test]
fn a_power_of_a_square_root_merges_with_its_base() {
    // a fuzzer finding: sqrt(T)*sqrt(T)/T printed as `T/(2*T)` once and `1/2` after a re-parse
    assert_eq!(p("sqrt(T)*sqrt(T)/T"), Expr::one());
    assert_eq!(p("T^-1*sqrt(T)^2"), Expr::one());
    assert_eq!(p("sqrt(T)^3/T").to_string(), p("sqrt(T)").to_string());
    let text = "12980---T**.5/-T*.5*---T**.5";
    assert_eq!(
        p(text),
        Expr::rational(num_rational::Rational64::new(25959, 2))
    );
    let once = p(text).to_string();
    assert_eq!(p(&once).to_string(), once);
}

/// Decimal printing (file writers): exact decimals for rationals that have one, the exact form
/// otherwise, and what prints reads back to the same expression.
#[test]
fn decimal_printing_reads_back_to_the_same_expression() {
    let cases = [
        ("0.705", "0.705"),
        ("-9.81", "-9.81"),
        ("141/200", "0.705"),
        ("1/3", "1/3"),
        ("pi/2", "pi/2"),
        ("-pi/2", "-pi/2"),
        ("2*pi/3", "2*pi/3"),
        ("0.705*d3 - 0.5*M3", "-M3/2 + 0.705*d3"),
        ("d3 + 0.00002896", "0.00002896 + d3"),
        ("1e-9", "0.000000001"),
        // 10 decimals: Expr::num would not read it back as this rational
        ("1/1024", "1/1024"),
        ("0.22094100000000003", "0.22094100000000003"),
        ("x^2*(-0.75)", "-0.75*x^2"),
        ("x^2*(-0.25)", "-x^2/4"),
        ("3", "3"),
    ];
    for (src, want) in cases {
        let e = Expr::parse(src).unwrap();
        let text = e.decimal().to_string();
        assert_eq!(text, want, "{src}");
        assert_eq!(Expr::parse(&text).unwrap(), e, "{src} -> {text}");
    }
    // the plain Display is unchanged (generated code and equations keep exact fractions)
    assert_eq!(Expr::parse("0.705").unwrap().to_string(), "141/200");
}

/// Hoisting the function calls moves every call and what it needs to the front, keeps both
/// groups in order, and changes no value.
#[test]
fn function_calls_are_hoisted_with_their_dependencies() {
    use crate::{Assignment, Program};
    let a = |name: &str, e: &str| Assignment {
        name: name.into(),
        expr: p(e),
    };
    let env = |s: &str| match s {
        "x" => Some(0.7),
        "y" => Some(-1.3),
        "q" => Some(0.4),
        _ => None,
    };
    // the order after hoisting; the outputs' values are checked unchanged
    let hoisted = |assignments: Vec<Assignment>, outputs: Vec<Assignment>| -> Vec<String> {
        let mut prog = Program {
            assignments,
            outputs,
            ..Program::default()
        };
        let before = prog.evaluate(&env).unwrap();
        prog.hoist_function_calls();
        assert_eq!(prog.evaluate(&env).unwrap(), before);
        prog.assignments.into_iter().map(|a| a.name).collect()
    };
    let chain = vec![
        a("A", "x*y"),
        a("T", "q + 1"),
        a("B", "A + x"),
        a("S", "sin(T)"),
        a("C", "B*S"),
    ];
    // D calls cos but also needs C, B, A: the whole chain moves; nothing stays behind here
    // but keeps its order
    let mut with_d = chain.clone();
    with_d.extend([a("U", "q*q"), a("D", "cos(U) + C")]);
    assert_eq!(
        hoisted(with_d, vec![a("OUT1", "D*A"), a("OUT2", "C + B")]),
        ["A", "T", "B", "S", "C", "U", "D"]
    );
    assert_eq!(
        hoisted(chain, vec![a("OUT", "C + A")]),
        ["T", "S", "A", "B", "C"]
    );
}

#[test]
fn odd_quarter_turns_give_one_number_for_sine_and_cosine() {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    // exact arguments and their float spelling (a URDF's rpy) give the same number
    for (s, v) in [
        ("cos(pi/4)", h),
        ("sin(pi/4)", h),
        ("cos(3*pi/4)", -h),
        ("sin(3*pi/4)", h),
        ("sin(-pi/4)", -h),
        ("cos(-pi/4)", h),
        ("sin(5*pi/4)", -h),
        ("cos(7*pi/4)", h),
        ("cos(0.7853981633974483)", h),
        ("sin(-0.7853981633974483)", -h),
    ] {
        assert_eq!(p(s).as_f64(), Some(v), "{s}");
    }
    assert_eq!(p("tan(3*pi/4)").as_f64(), Some(-1.0));
    // every value agrees with libm's at the rounded argument (a few ulps)
    for k in [-7, -5, -3, -1, 1, 3, 5, 7] {
        let x = k as f64 * std::f64::consts::FRAC_PI_4;
        let e = p(&format!("{k}*pi/4"));
        let s = Expr::func(crate::Func::Sin, e.clone()).as_f64().unwrap();
        let c = Expr::func(crate::Func::Cos, e).as_f64().unwrap();
        assert!(
            (s - x.sin()).abs() < 1e-15 && (c - x.cos()).abs() < 1e-15,
            "{k}"
        );
    }
    // a symbol in the argument keeps the function
    assert_eq!(p("cos(q2 - pi/4)").to_string(), "cos(-pi/4 + q2)");
}

#[test]
fn numeric_coefficients_equal_up_to_sign_are_factored() {
    use crate::{Assignment, Program};
    let env = |s: &str| match s {
        "x" => Some(0.7),
        "y" => Some(-1.3),
        "z" => Some(0.4),
        _ => None,
    };
    let prog = |e: &str| Program {
        outputs: vec![Assignment {
            name: "OUT".into(),
            expr: p(e),
        }],
        ..Program::default()
    };
    for (e, mul, add) in [
        // 3 multiplications -> 1
        ("0.7071*x - 0.7071*y + 0.7071*z", 1, 2),
        // x, then 3/2 (or the other way round): 4 multiplications -> 2
        ("x*y + x*z + 1.5*y - 1.5*z", 2, 3),
    ] {
        let mut a = prog(e);
        let before = a.evaluate(&env).unwrap();
        a.factor_sums();
        let n = a.count();
        assert_eq!((n.mul, n.add), (mul, add), "{e}: {}", a.outputs[0].expr);
        let after = a.evaluate(&env).unwrap();
        assert!((after[0] - before[0]).abs() < 1e-15, "{e}");
    }
}
