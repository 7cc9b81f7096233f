//! specula-cli's tests: the `specula` binary as users run it, and the documents, peers and
//! tools around it. One test binary, one module per subject, so that one link serves them all
//! and libtest runs them side by side: most wait on another program (the binary, Yosys, Python,
//! Mitsuba, Blender), which one binary per file ran one file at a time.
//!
//! `cargo test -p specula-cli --test suite readme::` runs one subject.

mod common;

mod bad_inputs;
mod blender;
mod cli;
mod design;
mod engines;
mod enhanced_dicom;
mod fit;
mod gpu;
mod hw;
mod interrupt;
mod isa;
mod materialx;
mod measured;
mod mitsuba;
mod mitsuba_microfacet;
mod python;
mod readme;
mod real_scans;
mod recommend;
mod render;
mod report;
mod sample;
mod sky;
mod structure;
mod user_lobe;
mod volume;
mod vtk;
