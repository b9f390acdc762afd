//! `solve`'s graph parser on arbitrary text: an error is one line; a parsed graph obeys the
//! format's rules and survives a write/parse round trip; small ones go through the solver too.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vgsel_colmap::flow::graph_file::{parse, write};
use vgsel_colmap::flow::search::{search, FlowRule};

fuzz_target!(|input: &[u8]| {
    let Ok(text) = std::str::from_utf8(input) else {
        return;
    };
    match parse(text) {
        Err(e) => assert!(!e.to_string().contains('\n'), "{e}"),
        Ok(problem) => {
            let v = problem.image_costs.len();
            for p in &problem.pairs {
                assert!(p.i < p.j && (p.j as usize) < v);
                assert!((-1.0..=0.0).contains(&p.cost));
            }
            assert_eq!(parse(&write(&problem)).unwrap(), problem);
            if v <= 64 && problem.pairs.len() <= 256 {
                let flow = (input.len() as u64 % 8) + 1;
                let result = search(&problem, &FlowRule::Fixed(flow));
                assert_eq!(result.selection.pairs.len(), problem.pairs.len());
            }
        }
    }
});
