//! The optimisation passes of a [`Program`]: dead assignments, aliases, single-use inlining,
//! common-subexpression sharing and factoring of sums.
//!
//! The passes are incremental, so that their cost stays close to linear in the program's size
//! (a serial chain of n links records O(n) assignments): an index maps each symbol to the
//! assignments that use it, the candidates of common-subexpression sharing are counted once and
//! their counts updated where a replacement changes an expression, and the best candidate is
//! kept in a priority queue. Expressions hash in O(1) (memoized), so counting them is cheap.

use crate::expr::{grow, Expr, Node};
use crate::program::{count_ops, is_trivial, Assignment, OpCount, Program};
use std::cmp::Ordering;
use std::collections::{BTreeMap, BinaryHeap, HashMap, HashSet};

/// Replace every occurrence of `target` (as a whole node, as a sub-product of a product's
/// factors or as a sub-sum of a sum's terms) by `by`. Sub-trees that cannot hold the target
/// (shallower than it) are kept as they are.
fn replace(e: &Expr, target: &Expr, by: &Expr) -> Expr {
    if e == target {
        return by.clone();
    }
    if e.depth() < target.depth() {
        return e.clone();
    }
    grow(|| match e.node() {
        Node::Add(v) | Node::Mul(v) => {
            let is_add = matches!(e.node(), Node::Add(_));
            let mut items: Vec<Expr> = v.iter().map(|t| replace(t, target, by)).collect();
            let mut changed = items.iter().zip(v).any(|(a, b)| a != b);
            match (e.node(), target.node()) {
                (Node::Add(_), Node::Add(tt)) if contains_all(&items, tt) => {
                    remove_all(&mut items, tt);
                    items.push(by.clone());
                    changed = true;
                }
                (Node::Mul(_), Node::Mul(tt)) if !tt[0].is_number() && contains_all(&items, tt) => {
                    remove_all(&mut items, tt);
                    items.push(by.clone());
                    changed = true;
                }
                _ => {}
            }
            if !changed {
                e.clone()
            } else if is_add {
                Expr::sum(items)
            } else {
                Expr::product(items)
            }
        }
        Node::Pow(..) | Node::Func(..) | Node::Atan2(..) => {
            e.map_children(&|c| replace(c, target, by), &|_| None)
        }
        _ => e.clone(),
    })
}

fn contains_all(hay: &[Expr], needles: &[Expr]) -> bool {
    let mut used = vec![false; hay.len()];
    needles.iter().all(
        |n| match hay.iter().enumerate().position(|(i, h)| !used[i] && h == n) {
            Some(i) => {
                used[i] = true;
                true
            }
            None => false,
        },
    )
}

fn remove_all(hay: &mut Vec<Expr>, needles: &[Expr]) {
    for n in needles {
        if let Some(i) = hay.iter().position(|h| h == n) {
            hay.remove(i);
        }
    }
}

/// Sums and products of more items than this contribute no pairs of items as candidates.
const MAX_PAIR_ITEMS: usize = 24;

/// Candidate common subexpressions of `e`: whole sub-nodes and pairs of factors / terms (the
/// root itself when `root` is false).
fn collect_candidates(e: &Expr, root: bool, out: &mut Vec<Expr>) {
    grow(|| match e.node() {
        Node::Add(v) | Node::Mul(v) => {
            if !root {
                out.push(e.clone());
            }
            let is_mul = matches!(e.node(), Node::Mul(_));
            let items: Vec<&Expr> = v.iter().filter(|t| !(is_mul && t.is_number())).collect();
            // pairs of a long sum (a row of the direct model's L D L' factorization has as many
            // terms as joints) would be quadratic in its length, and rarely recur elsewhere
            if items.len() > 2 && items.len() <= MAX_PAIR_ITEMS {
                for a in 0..items.len() {
                    for b in a + 1..items.len() {
                        out.push(if is_mul {
                            Expr::product([items[a].clone(), items[b].clone()])
                        } else {
                            Expr::sum([items[a].clone(), items[b].clone()])
                        });
                    }
                }
            }
            v.iter().for_each(|t| collect_candidates(t, false, out));
        }
        Node::Pow(b, n) => {
            if !root && *n > 1 {
                out.push(e.clone());
            }
            collect_candidates(b, false, out)
        }
        Node::Func(_, a) => {
            if !root {
                out.push(e.clone());
            }
            collect_candidates(a, false, out)
        }
        Node::Atan2(y, x) => {
            if !root {
                out.push(e.clone());
            }
            collect_candidates(y, false, out);
            collect_candidates(x, false, out)
        }
        _ => {}
    })
}

/// The candidates of a whole assignment: its sub-nodes and pairs, and the root itself when it
/// is not trivial (a root counts as an occurrence).
fn candidates_of(e: &Expr) -> Vec<Expr> {
    let mut out = Vec::new();
    collect_candidates(e, true, &mut out);
    if !is_trivial(e) {
        out.push(e.clone());
    }
    out
}

/// The magnitude |c| of a numeric coefficient c other than 0 and +-1: terms whose coefficients
/// are +-c share it as a factor (`c*x - c*y` -> `c*(x - y)`).
fn magnitude(c: &Expr) -> Option<Expr> {
    let x = c.as_f64()?;
    if x == 0.0 || x.abs() == 1.0 {
        return None;
    }
    Some(if x < 0.0 { -c.clone() } else { c.clone() })
}

/// Recursive greedy factoring of symbols common to terms of sums (see [`Program::factor_sums`]);
/// with `numbers`, also of numeric coefficients equal up to their sign, and again among the
/// terms left after each factoring.
fn factor(e: &Expr, numbers: bool) -> Expr {
    let rec = |x: &Expr| factor(x, numbers);
    grow(|| match e.node() {
        Node::Add(v) => {
            let terms: Vec<Expr> = v.iter().map(rec).collect();
            // symbol factors of each term, and its numeric coefficient up to its sign
            let mut freq: HashMap<Expr, usize> = HashMap::new();
            for t in &terms {
                if let Node::Mul(fs) = t.node() {
                    let mut seen: Vec<&Expr> = Vec::new();
                    for f in fs {
                        if matches!(f.node(), Node::Symbol(_)) && !seen.contains(&f) {
                            seen.push(f);
                            *freq.entry(f.clone()).or_default() += 1;
                        }
                    }
                    if let Some(c) = magnitude(&fs[0]).filter(|_| numbers) {
                        *freq.entry(c).or_default() += 1;
                    }
                }
            }
            let best = freq
                .into_iter()
                .filter(|(_, n)| *n >= 2)
                .max_by(|a, b| a.1.cmp(&b.1).then_with(|| crate::cmp_expr(&b.0, &a.0)));
            let Some((f, _)) = best else {
                return Expr::sum(terms);
            };
            let mut inner = Vec::new();
            let mut rest = Vec::new();
            for t in terms {
                let has = matches!(t.node(), Node::Mul(fs)
                    if fs.contains(&f) || (numbers && magnitude(&fs[0]).as_ref() == Some(&f)));
                if has {
                    inner.push(t / f.clone());
                } else {
                    rest.push(t);
                }
            }
            let factored = Expr::product([f, rec(&Expr::sum(inner))]);
            if !numbers || rest.len() < 2 {
                rest.push(factored);
                return Expr::sum(rest);
            }
            // the other terms may share another factor
            Expr::sum([rec(&Expr::sum(rest)), factored])
        }
        Node::Mul(v) => Expr::product(v.iter().map(rec)),
        _ => e.map_children(&rec, &|_| None),
    })
}

/// The slots of a program being optimised: its assignments, then its outputs, then the
/// assignments the passes add; a removed slot is `None`. Each symbol maps to the slots that use
/// it (with the number of uses).
struct Slots {
    slots: Vec<Option<Slot>>,
    users: HashMap<String, BTreeMap<usize, usize>>,
}

struct Slot {
    name: String,
    expr: Expr,
    output: bool,
}

impl Slots {
    fn new(p: &mut Program) -> Slots {
        let mut s = Slots {
            slots: Vec::new(),
            users: HashMap::new(),
        };
        for a in p.assignments.drain(..) {
            s.push(a, false);
        }
        for o in p.outputs.drain(..) {
            s.push(o, true);
        }
        s
    }

    fn push(&mut self, a: Assignment, output: bool) -> usize {
        let k = self.slots.len();
        self.index(k, &a.expr, true);
        self.slots.push(Some(Slot {
            name: a.name,
            expr: a.expr,
            output,
        }));
        k
    }

    /// Add (or remove) the symbol uses of `e`, the expression of slot `k`, to the index.
    fn index(&mut self, k: usize, e: &Expr, add: bool) {
        let users = &mut self.users;
        e.for_each_symbol(&mut |s| {
            if add {
                *users
                    .entry(s.to_string())
                    .or_default()
                    .entry(k)
                    .or_default() += 1;
            } else if let Some(m) = users.get_mut(s) {
                if let Some(c) = m.get_mut(&k) {
                    *c -= 1;
                    if *c == 0 {
                        m.remove(&k);
                    }
                }
            }
        });
    }

    fn get(&self, k: usize) -> &Slot {
        self.slots[k].as_ref().expect("a live slot")
    }

    /// Give slot `k` a new expression.
    fn set(&mut self, k: usize, e: Expr) {
        let old = std::mem::replace(&mut self.slots[k].as_mut().expect("live").expr, e.clone());
        self.index(k, &old, false);
        self.index(k, &e, true);
    }

    fn remove(&mut self, k: usize) -> Slot {
        let s = self.slots[k].take().expect("a live slot");
        self.index(k, &s.expr, false);
        s
    }

    /// Number of uses of a symbol.
    fn uses(&self, name: &str) -> usize {
        self.users.get(name).map_or(0, |m| m.values().sum())
    }

    /// The slots using a symbol, in slot order.
    fn users_of(&self, name: &str) -> Vec<usize> {
        self.users
            .get(name)
            .map(|m| m.keys().copied().collect())
            .unwrap_or_default()
    }

    /// Back to a program: the live assignments in slot order, each assignment the passes added
    /// placed just before its first user (its own dependencies first), then the outputs.
    fn into_program(self, p: &mut Program, added_from: usize) {
        let Slots { mut slots, .. } = self;
        let added: HashMap<String, usize> = (added_from..slots.len())
            .filter_map(|k| slots[k].as_ref().map(|s| (s.name.clone(), k)))
            .collect();
        let mut emitted = vec![false; slots.len()];
        let mut order: Vec<usize> = Vec::with_capacity(slots.len());
        for k in 0..slots.len() {
            if slots[k].is_none() || emitted[k] || (k >= added_from && !added.is_empty()) {
                continue;
            }
            // depth-first over the added assignments this slot needs (explicit stack)
            let mut stack = vec![(k, false)];
            while let Some((s, expanded)) = stack.pop() {
                if emitted[s] {
                    continue;
                }
                if expanded {
                    emitted[s] = true;
                    order.push(s);
                    continue;
                }
                stack.push((s, true));
                let mut deps = Vec::new();
                if let Some(sl) = &slots[s] {
                    sl.expr.for_each_symbol(&mut |n| {
                        if let Some(&d) = added.get(n) {
                            if !emitted[d] && !deps.contains(&d) {
                                deps.push(d);
                            }
                        }
                    });
                }
                for d in deps.into_iter().rev() {
                    stack.push((d, false));
                }
            }
        }
        for k in order {
            let s = slots[k].take().expect("live");
            let a = Assignment {
                name: s.name,
                expr: s.expr,
            };
            if s.output {
                p.outputs.push(a);
            } else {
                p.assignments.push(a);
            }
        }
    }
}

/// An entry of the candidates' priority queue: the larger saving first; among equal savings
/// the smaller expression (structural order, then text), so that the choice never depends on
/// hashing.
struct Best {
    saving: usize,
    expr: Expr,
}

impl PartialEq for Best {
    fn eq(&self, o: &Best) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Best {}
impl PartialOrd for Best {
    fn partial_cmp(&self, o: &Best) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Best {
    fn cmp(&self, o: &Best) -> Ordering {
        self.saving
            .cmp(&o.saving)
            .then_with(|| crate::cmp_expr(&o.expr, &self.expr))
            .then_with(|| o.expr.to_string().cmp(&self.expr.to_string()))
    }
}

/// How often each candidate occurs, in which slots, and the best one.
#[derive(Default)]
struct Candidates {
    /// candidate -> (operations, occurrences per slot)
    info: HashMap<Expr, (usize, BTreeMap<usize, usize>)>,
    /// the candidates of each slot, as registered
    of_slot: HashMap<usize, Vec<Expr>>,
    queue: BinaryHeap<Best>,
}

impl Candidates {
    fn count(&self, e: &Expr) -> usize {
        self.info.get(e).map_or(0, |(_, m)| m.values().sum())
    }

    fn saving(&self, e: &Expr) -> usize {
        match self.info.get(e) {
            Some((ops, m)) => m.values().sum::<usize>().saturating_sub(1) * ops,
            None => 0,
        }
    }

    fn register(&mut self, k: usize, e: &Expr) {
        let cands = candidates_of(e);
        for c in &cands {
            let (_, m) = self.info.entry(c.clone()).or_insert_with(|| {
                let o = count_ops(c);
                (o.mul + o.add + o.func, BTreeMap::new())
            });
            *m.entry(k).or_default() += 1;
        }
        let mut seen = HashSet::new();
        for c in &cands {
            if seen.insert(c) && self.count(c) >= 2 {
                let saving = self.saving(c);
                if saving > 0 {
                    self.queue.push(Best {
                        saving,
                        expr: c.clone(),
                    });
                }
            }
        }
        self.of_slot.insert(k, cands);
    }

    fn unregister(&mut self, k: usize) {
        let Some(cands) = self.of_slot.remove(&k) else {
            return;
        };
        for c in &cands {
            if let Some((_, m)) = self.info.get_mut(c) {
                if let Some(n) = m.get_mut(&k) {
                    *n -= 1;
                    if *n == 0 {
                        m.remove(&k);
                    }
                }
            }
        }
        let mut seen = HashSet::new();
        for c in &cands {
            if seen.insert(c) {
                let saving = self.saving(c);
                if self.count(c) >= 2 && saving > 0 {
                    self.queue.push(Best {
                        saving,
                        expr: c.clone(),
                    });
                } else if self.count(c) == 0 {
                    self.info.remove(c);
                }
            }
        }
    }

    /// The best candidate not yet extracted, if any saves operations.
    fn pop(&mut self, done: &HashSet<Expr>) -> Option<Expr> {
        while let Some(b) = self.queue.pop() {
            if done.contains(&b.expr) || self.count(&b.expr) < 2 {
                continue;
            }
            if self.saving(&b.expr) != b.saving {
                continue; // stale: a fresher entry is in the queue
            }
            return Some(b.expr);
        }
        None
    }
}

impl Program {
    /// Remove assignments no output depends on.
    pub fn remove_dead(&mut self) {
        let mut live: HashSet<String> = HashSet::new();
        let add = |e: &Expr, live: &mut HashSet<String>| {
            e.for_each_symbol(&mut |s| {
                if !live.contains(s) {
                    live.insert(s.to_string());
                }
            });
        };
        for o in &self.outputs {
            add(&o.expr, &mut live);
        }
        let mut keep = vec![false; self.assignments.len()];
        for (i, a) in self.assignments.iter().enumerate().rev() {
            if live.contains(&a.name) {
                keep[i] = true;
                add(&a.expr, &mut live);
            }
        }
        let mut k = keep.into_iter();
        self.assignments.retain(|_| k.next().unwrap());
    }

    /// Replace assignments whose value is trivial (a symbol, a number, a negated symbol) by
    /// their value where they are used.
    pub fn remove_aliases(&mut self) {
        let mut map: HashMap<String, Expr> = HashMap::new();
        let mut out = Vec::with_capacity(self.assignments.len());
        for a in self.assignments.drain(..) {
            let e = if map.is_empty() {
                a.expr
            } else {
                a.expr.substitute(&|s| map.get(s).cloned())
            };
            if is_trivial(&e) {
                map.insert(a.name, e);
            } else {
                out.push(Assignment {
                    name: a.name,
                    expr: e,
                });
            }
        }
        self.assignments = out;
        if !map.is_empty() {
            for o in &mut self.outputs {
                o.expr = o.expr.substitute(&|s| map.get(s).cloned());
            }
        }
    }

    /// Inline assignments used exactly once when that lowers the operation count (constants
    /// fold, like terms merge), or when the single user is a plain copy of it (`GAMCL4 = GAM4`).
    /// One step further too: when the user is itself an assignment used once, inlining both into
    /// its user may pay (terms cancel: `GAMCL2 = N32 - N33`, `N32 = NDI33 + No32`,
    /// `NDI33 = N33 + ...`).
    pub fn inline_single_use(&mut self) {
        let n = self.assignments.len();
        let mut s = Slots::new(self);
        let ops = |o: OpCount| o.mul + o.add;
        let single_user = |s: &Slots, name: &str| -> Option<usize> {
            (s.uses(name) == 1).then(|| s.users_of(name)[0])
        };
        for i in 0..n {
            let Some(slot) = &s.slots[i] else { continue };
            let (name, def) = (slot.name.clone(), slot.expr.clone());
            let Some(u) = single_user(&s, &name) else {
                continue;
            };
            let user = s.get(u).expr.clone();
            let before = count_ops(&user) + count_ops(&def);
            let after_expr = user.substitute(&|x| (x == name).then(|| def.clone()));
            let after = count_ops(&after_expr);
            let copy = user.as_symbol() == Some(name.as_str());
            if copy || ops(after) < ops(before) {
                s.set(u, after_expr);
                s.remove(i);
                continue;
            }
            if s.get(u).output {
                continue;
            }
            let uname = s.get(u).name.clone();
            let Some(u2) = single_user(&s, &uname) else {
                continue;
            };
            let user2 = s.get(u2).expr.clone();
            let before2 = before + count_ops(&user2);
            let after2_expr = user2.substitute(&|x| (x == uname).then(|| after_expr.clone()));
            if ops(count_ops(&after2_expr)) < ops(before2) {
                s.set(u2, after2_expr);
                s.remove(u);
                s.remove(i);
            }
        }
        s.into_program(self, usize::MAX);
    }

    /// Share common subexpressions (whole sub-nodes, pairs of factors of products and pairs of
    /// terms of sums) greedily, the largest saving first, as new assignments `T1, T2, ...`
    /// placed before their first use.
    pub fn share_common_subexpressions(&mut self) {
        let reserved: HashSet<String> = self
            .assignments
            .iter()
            .chain(&self.outputs)
            .map(|a| a.name.clone())
            .chain(self.input_symbols())
            .collect();
        let mut s = Slots::new(self);
        let added_from = s.slots.len();
        let mut cands = Candidates::default();
        for k in 0..s.slots.len() {
            let e = s.get(k).expr.clone();
            cands.register(k, &e);
        }
        let mut counter = 0;
        // targets already extracted: never extracted twice (guards against a candidate whose
        // occurrences do not all match as counted)
        let mut done: HashSet<Expr> = HashSet::new();
        while let Some(target) = cands.pop(&done) {
            done.insert(target.clone());
            let name = loop {
                counter += 1;
                let n = format!("T{counter}");
                if !reserved.contains(&n) {
                    break n;
                }
            };
            let sym = Expr::symbol(name.clone());
            let changed = replace_in_slots(&mut s, &mut cands, &target, &sym);
            if changed.is_empty() {
                continue;
            }
            let k = s.push(
                Assignment {
                    name,
                    expr: target.clone(),
                },
                false,
            );
            cands.register(k, &target);
            // an assignment whose value became trivial (exactly T): an alias, replaced by its
            // value where it is used
            let mut work: Vec<usize> = changed;
            while let Some(k) = work.pop() {
                let Some(slot) = &s.slots[k] else { continue };
                if slot.output || !is_trivial(&slot.expr) {
                    continue;
                }
                let (alias, value) = (slot.name.clone(), slot.expr.clone());
                cands.unregister(k);
                s.remove(k);
                for u in s.users_of(&alias) {
                    let e = s
                        .get(u)
                        .expr
                        .substitute(&|x| (x == alias).then(|| value.clone()));
                    cands.unregister(u);
                    s.set(u, e.clone());
                    cands.register(u, &e);
                    work.push(u);
                }
            }
        }
        s.into_program(self, added_from);
    }

    /// Factor a symbol common to several terms of a sum: `a*x + b*x + c` -> `x*(a + b) + c`
    /// (saves one multiplication per extra term), or a numeric coefficient equal up to its sign:
    /// `k*x - k*y` -> `k*(x - y)`; greedily, the most frequent factor first.
    pub fn factor_sums(&mut self) {
        self.factor_sums_with(true);
    }

    /// [`Program::factor_sums`]; without `numbers`, symbols only.
    fn factor_sums_with(&mut self, numbers: bool) {
        for a in self.assignments.iter_mut().chain(self.outputs.iter_mut()) {
            a.expr = factor(&a.expr, numbers);
        }
    }

    /// All passes: dead assignments, aliases, single-use inlining, then the best (fewest
    /// operations) of common-subexpression sharing alone, after factoring the sums' symbols, or
    /// after factoring their symbols and numeric coefficients.
    pub fn optimize(&mut self) {
        self.optimize_with_progress(&mut |_| {});
    }

    /// [`Program::optimize`], calling `progress` with the name of each pass as it starts (a long
    /// generation can show what it is doing).
    pub fn optimize_with_progress(&mut self, progress: &mut dyn FnMut(&str)) {
        progress("removing dead code and aliases");
        self.remove_dead();
        self.remove_aliases();
        progress("inlining single-use intermediates");
        self.inline_single_use();
        let unshared = self.clone();
        progress("sharing common subexpressions");
        self.share_common_subexpressions();
        self.inline_single_use();
        self.remove_dead();
        // factoring symbols only, or numeric coefficients too: either can share better
        for numbers in [false, true] {
            progress("factoring sums, then sharing common subexpressions");
            let mut factored = unshared.clone();
            factored.factor_sums_with(numbers);
            factored.share_common_subexpressions();
            factored.inline_single_use();
            factored.remove_dead();
            let (a, b) = (self.count(), factored.count());
            if b.mul + b.add < a.mul + a.add {
                *self = factored;
            }
        }
        self.name_outputs();
        self.hoist_function_calls();
    }

    /// Move the function calls (sin, cos, sign, sqrt) and the assignments they depend on to
    /// the front, each group keeping its order (SYMORO's layout: the sines and cosines of the
    /// joint angles first). Generated code then calls no function in the middle of its
    /// arithmetic, where every live intermediate would be saved around the call (no
    /// floating-point register survives a call in the C calling conventions). No operation
    /// changes.
    pub fn hoist_function_calls(&mut self) {
        let index: HashMap<&str, usize> = self
            .assignments
            .iter()
            .enumerate()
            .map(|(i, a)| (a.name.as_str(), i))
            .collect();
        let mut hoist = vec![false; self.assignments.len()];
        // backwards: an assignment is hoisted if it calls a function or a hoisted one uses it
        for i in (0..self.assignments.len()).rev() {
            let e = &self.assignments[i].expr;
            if !hoist[i] && count_ops(e).func == 0 {
                continue;
            }
            hoist[i] = true;
            e.for_each_symbol(&mut |s| {
                if let Some(&k) = index.get(s) {
                    hoist[k] = true;
                }
            });
        }
        let (mut front, mut back) = (Vec::new(), Vec::new());
        for (a, h) in self.assignments.drain(..).zip(hoist) {
            if h {
                front.push(a);
            } else {
                back.push(a);
            }
        }
        front.append(&mut back);
        self.assignments = front;
    }

    /// An output that is a copy of an intermediate (`W3_1 = X2_1`, `QDP2 = X2`) gives that
    /// intermediate its own name, so that the equations read `W3_1 = ...` once. Inputs,
    /// intermediates copied by several outputs beyond the first, and elementary function calls
    /// (`S1 = sin(q1)` stays `S1`, as SYMORO writes it, when a Jacobian entry is S1) keep theirs.
    /// No operation changes.
    pub fn name_outputs(&mut self) {
        let assigned: HashSet<&str> = self
            .assignments
            .iter()
            .filter(|a| !matches!(a.expr.node(), Node::Func(..)))
            .map(|a| a.name.as_str())
            .collect();
        let taken: HashSet<String> = self
            .input_symbols()
            .into_iter()
            .chain(self.assignments.iter().map(|a| a.name.clone()))
            .collect();
        let mut map: HashMap<String, Expr> = HashMap::new();
        for o in &self.outputs {
            let Some(s) = o.expr.as_symbol() else {
                continue;
            };
            if assigned.contains(s) && !map.contains_key(s) && !taken.contains(&o.name) {
                map.insert(s.to_string(), Expr::symbol(o.name.clone()));
            }
        }
        if map.is_empty() {
            return;
        }
        let rename = |e: &Expr| e.substitute(&|s| map.get(s).cloned());
        for a in &mut self.assignments {
            if let Some(n) = map.get(&a.name).and_then(Expr::as_symbol) {
                a.name = n.to_string();
            }
            a.expr = rename(&a.expr);
        }
        for o in &mut self.outputs {
            o.expr = rename(&o.expr);
        }
    }
}

/// Replace `target` by `sym` in every slot that may hold it; returns the slots changed. The
/// slots searched are those where the target was counted, and for a sum or a product (which may
/// also sit inside a larger one, uncounted) those using its rarest symbol.
fn replace_in_slots(
    s: &mut Slots,
    cands: &mut Candidates,
    target: &Expr,
    sym: &Expr,
) -> Vec<usize> {
    let mut search: Vec<usize> = cands
        .info
        .get(target)
        .map(|(_, m)| m.keys().copied().collect())
        .unwrap_or_default();
    // a sum or product may also match inside a larger one (`a*b` in `2*a*b`, `a + b + c` in
    // `a + b + c + d`), where it was not counted
    let wide = matches!(target.node(), Node::Add(_) | Node::Mul(_));
    if wide {
        let symbols = target.symbols();
        match symbols
            .iter()
            .min_by_key(|x| s.users.get(x.as_str()).map_or(0, |m| m.len()))
        {
            Some(rarest) => {
                for k in s.users_of(rarest) {
                    search.push(k);
                }
            }
            None => search.extend((0..s.slots.len()).filter(|&k| s.slots[k].is_some())),
        }
        search.sort_unstable();
        search.dedup();
    }
    let mut changed = Vec::new();
    for k in search {
        let Some(slot) = &s.slots[k] else { continue };
        let r = replace(&slot.expr, target, sym);
        if r != slot.expr {
            cands.unregister(k);
            s.set(k, r.clone());
            cands.register(k, &r);
            changed.push(k);
        }
    }
    changed
}
