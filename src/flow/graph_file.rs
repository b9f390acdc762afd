//! The plain-text graph format of `vgsel-colmap solve`: line 1 `V E`; then V lines, one image
//! cost each; then E lines `i j cost` (0-based, i < j); costs in [-1, 0].
//!
//! Tokens are separated by ASCII whitespace; CRLF line ends, trailing whitespace and blank lines
//! after the last pair line are accepted. Anything else is an error naming the 1-based line.
//! Duplicate pairs are not detected. [`write()`] produces the format, round-tripping costs exactly.

use crate::network::{PairArc, SelectionProblem};
use anyhow::{bail, Result};
use std::fmt::Write as _;

fn parse_cost(tok: &str, line: usize, what: &str) -> Result<f64> {
    let c: f64 = match tok.parse() {
        Ok(c) => c,
        Err(_) => bail!("line {line}: bad number {tok:?} for {what}"),
    };
    if !(-1.0..=0.0).contains(&c) {
        bail!("line {line}: {what} {tok} outside [-1, 0]");
    }
    Ok(c)
}

fn parse_int<T: std::str::FromStr>(tok: &str, line: usize, what: &str) -> Result<T> {
    match tok.parse() {
        Ok(v) => Ok(v),
        Err(_) => bail!("line {line}: bad number {tok:?} for {what}"),
    }
}

/// Reads a selection problem in this format; an error names the 1-based line and what is wrong.
pub fn parse(text: &str) -> Result<SelectionProblem> {
    // Trailing whitespace and blank lines at the end are not content.
    let body = text.trim_end_matches(|c: char| c.is_ascii_whitespace());
    let mut lines = body
        .split('\n')
        .enumerate()
        .map(|(k, l)| (k + 1, l.strip_suffix('\r').unwrap_or(l)));

    let (_, header) = lines.next().unwrap_or((1, ""));
    let mut tok = header.split_ascii_whitespace();
    let (Some(v_tok), Some(e_tok)) = (tok.next(), tok.next()) else {
        bail!("line 1: expected header `V E` (image and pair counts)");
    };
    if let Some(extra) = tok.next() {
        bail!("line 1: unexpected {extra:?} after `V E`");
    }
    let v: u32 = parse_int(v_tok, 1, "image count V")?;
    let e: u64 = parse_int(e_tok, 1, "pair count E")?;
    let v = v as usize;

    // Capacity hints bounded by the text size, so a bogus header cannot allocate wildly.
    let mut image_costs = Vec::with_capacity(v.min(text.len() / 2 + 1));
    for k in 0..v {
        let Some((ln, line)) = lines.next() else {
            bail!("file ends after {k} of {v} image cost lines");
        };
        let mut tok = line.split_ascii_whitespace();
        let Some(c) = tok.next() else {
            bail!("line {ln}: expected image cost {k} of {v}, found a blank line");
        };
        if let Some(extra) = tok.next() {
            bail!("line {ln}: unexpected {extra:?} after image cost (one cost per image line)");
        }
        image_costs.push(parse_cost(c, ln, "image cost")?);
    }

    let mut pairs = Vec::with_capacity((e as usize).min(text.len() / 6 + 1));
    for k in 0..e {
        let Some((ln, line)) = lines.next() else {
            bail!("file ends after {k} of {e} pair lines");
        };
        let mut tok = line.split_ascii_whitespace();
        let (Some(i), Some(j), Some(c)) = (tok.next(), tok.next(), tok.next()) else {
            bail!("line {ln}: expected pair `i j cost` ({} of {e})", k + 1);
        };
        if let Some(extra) = tok.next() {
            bail!("line {ln}: unexpected {extra:?} after `i j cost`");
        }
        let i: u32 = parse_int(i, ln, "image index i")?;
        let j: u32 = parse_int(j, ln, "image index j")?;
        if i as usize >= v || j as usize >= v {
            bail!("line {ln}: image index out of range in pair ({i}, {j}); V = {v}");
        }
        if i >= j {
            bail!("line {ln}: pair ({i}, {j}) needs i < j");
        }
        let cost = parse_cost(c, ln, "pair cost")?;
        pairs.push(PairArc { i, j, cost });
    }

    for (ln, line) in lines {
        if !line.trim_ascii().is_empty() {
            bail!("line {ln}: unexpected content after the {e} pair lines");
        }
    }
    Ok(SelectionProblem { image_costs, pairs })
}

/// Writes `problem` in the format [`parse`] reads (shortest round-tripping float notation).
pub fn write(problem: &SelectionProblem) -> String {
    let mut s = String::with_capacity(16 + 24 * (problem.image_costs.len() + problem.pairs.len()));
    let _ = writeln!(s, "{} {}", problem.image_costs.len(), problem.pairs.len());
    for c in &problem.image_costs {
        let _ = writeln!(s, "{c}");
    }
    for p in &problem.pairs {
        let _ = writeln!(s, "{} {} {}", p.i, p.j, p.cost);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        let e = parse(text).expect_err("expected a parse error");
        let msg = e.to_string();
        assert!(!msg.contains('\n'), "multi-line message: {msg}");
        msg
    }

    #[test]
    fn parses_example_with_crlf_and_trailing_blanks() {
        let p = parse("3 2\r\n-0.5\r\n0  \r\n-1\n0 1 -0.25\n1 2 0\n\n  \n").unwrap();
        assert_eq!(p.image_costs, vec![-0.5, 0.0, -1.0]);
        assert_eq!(p.pairs.len(), 2);
        assert_eq!((p.pairs[0].i, p.pairs[0].j, p.pairs[0].cost), (0, 1, -0.25));
        assert_eq!((p.pairs[1].i, p.pairs[1].j, p.pairs[1].cost), (1, 2, 0.0));
    }

    #[test]
    fn round_trip_is_exact() {
        let mut image_costs = Vec::new();
        let mut pairs = Vec::new();
        let mut x = 0.123456789f64;
        for i in 0..50u32 {
            x = (x * 7.77).fract();
            image_costs.push(-x);
            if i > 0 {
                pairs.push(PairArc {
                    i: i - 1,
                    j: i,
                    cost: -(x * 0.3).fract(),
                });
                pairs.push(PairArc {
                    i: 0,
                    j: i,
                    cost: -1.0 / (i as f64 + 1.0),
                });
            }
        }
        image_costs[3] = -1.0;
        image_costs[4] = 0.0;
        image_costs[5] = -f64::MIN_POSITIVE;
        let p = SelectionProblem { image_costs, pairs };
        assert_eq!(parse(&write(&p)).unwrap(), p);
        let empty = SelectionProblem::default();
        assert_eq!(parse(&write(&empty)).unwrap(), empty);
        assert_eq!(parse("0 0").unwrap(), empty);
    }

    #[test]
    fn error_cases_name_line_and_problem() {
        assert!(err("").contains("line 1"));
        assert!(err("3").contains("line 1"));
        assert!(err("3 x\n").contains("bad number"));
        assert!(err("-3 1\n").contains("bad number"));
        assert!(err("1 0 7\n-0.5\n").contains("line 1: unexpected"));
        let m = err("2 1\n-0.5\nabc\n0 1 -1\n");
        assert!(m.contains("line 3") && m.contains("bad number"), "{m}");
        let m = err("2 1\n-0.5\n0.5\n0 1 -1\n");
        assert!(m.contains("line 3") && m.contains("outside"), "{m}");
        let m = err("2 1\n-0.5\n-1.0000001\n0 1 -1\n");
        assert!(m.contains("line 3") && m.contains("outside"), "{m}");
        let m = err("2 1\n-0.5\nNaN\n0 1 -1\n");
        assert!(m.contains("line 3") && m.contains("outside"), "{m}");
        let m = err("2 1\n-0.5\n-0.1 -0.2\n0 1 -1\n");
        assert!(m.contains("line 3") && m.contains("unexpected"), "{m}");
        let m = err("2 1\n-0.5\n\n0 1 -1\n");
        assert!(m.contains("line 3") && m.contains("blank"), "{m}");
        let m = err("2 1\n-0.5\n-0.5\n1 0 -1\n");
        assert!(m.contains("line 4") && m.contains("i < j"), "{m}");
        let m = err("2 1\n-0.5\n-0.5\n1 1 -1\n");
        assert!(m.contains("line 4") && m.contains("i < j"), "{m}");
        let m = err("2 1\n-0.5\n-0.5\n0 2 -1\n");
        assert!(m.contains("line 4") && m.contains("out of range"), "{m}");
        let m = err("2 1\n-0.5\n-0.5\n0 1.5 -1\n");
        assert!(m.contains("line 4") && m.contains("bad number"), "{m}");
        let m = err("2 1\n-0.5\n-0.5\n0 1 inf\n");
        assert!(m.contains("line 4") && m.contains("outside"), "{m}");
        let m = err("2 1\n-0.5\n-0.5\n0 1\n");
        assert!(m.contains("line 4") && m.contains("expected pair"), "{m}");
        let m = err("2 1\n-0.5\n-0.5\n0 1 -1 9\n");
        assert!(m.contains("line 4") && m.contains("unexpected"), "{m}");
        // wrong counts
        let m = err("3 1\n-0.5\n-0.5\n");
        assert!(m.contains("2 of 3 image"), "{m}");
        let m = err("2 2\n-0.5\n-0.5\n0 1 -1\n");
        assert!(m.contains("1 of 2 pair"), "{m}");
        let m = err("2 1\n-0.5\n-0.5\n0 1 -1\n0 1 -1\n");
        assert!(
            m.contains("line 5") && m.contains("after the 1 pair lines"),
            "{m}"
        );
        let m = err("2 1\n-0.5\n-0.5\n0 1 -1\n\nx\n");
        assert!(m.contains("line 6"), "{m}");
    }
}
