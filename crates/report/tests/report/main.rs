//! tricept-report's tests, through the door (`tricept_ident::report`), on
//! calibrations, checks and exports the door makes from the fixtures and
//! from campaigns simulated here: what the page refuses, what its verdict
//! says for what was hidden in the campaigns, and the page in a real
//! browser. The sample page of docs/ is checked by `tests/sample.rs`.

mod browser;
mod refusals;
mod support;
mod verdicts;
mod webdriver;
