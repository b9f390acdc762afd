//! The plain-text graph format of `vgsel-colmap solve`: line 1 `V E`; then V lines, one image
//! cost each; then E lines `i j cost` (0-based, i < j); costs in [-1, 0].
//! (helper "solver" implements)

use crate::network::SelectionProblem;

pub fn parse(_text: &str) -> anyhow::Result<SelectionProblem> {
    todo!()
}
