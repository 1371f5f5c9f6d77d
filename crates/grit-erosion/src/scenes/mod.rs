//! The scenes a campaign runs, each in its folder: the impact of seed section 4
//! ([`impact`]) and the abrasive water jet of the AWJ paper ([`jet`]).

pub mod impact;
pub mod jet;
