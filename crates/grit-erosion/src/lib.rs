//! grit-erosion: the science around the SPH engine (seed paper section 4).
#![warn(missing_docs)]
