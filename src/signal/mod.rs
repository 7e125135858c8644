//! Signal processing that knows no gait: the mean filter, Lu's low-pass, and the
//! interpolation across short holes ([`bridge`]). Their arithmetic is [`crate::fixed`].

pub mod bridge;
pub mod low_pass;
pub mod mean_filter;
