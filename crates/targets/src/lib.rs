//! specula's lobes for the renderers people ship, generated from one description.
//!
//! A prepared lobe's formula is recorded once ([`specula::expression`]); each module here
//! writes that record in one target's language, so a lobe added to specula reaches every
//! target with no code of its own:
//! - [`wgsl`]: the WGSL function behind `specula shader` (and, through naga, GLSL, HLSL, MSL
//!   and SPIR-V);
//! - [`osl`]: a Blender Cycles script node (OSL);
//! - [`code`]: the straight-line writer they share.

pub mod code;
pub mod osl;
pub mod wgsl;
