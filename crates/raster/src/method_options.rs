//! The options every method shares, appended to each method's own by one macro
//! ([`method_options!`](crate::method_options)), so that no registry entry lists them.

/// A method's options for its [`MethodEntry::options`](crate::method::MethodEntry::options): its own, then the options every
/// method shares, appended here so no entry lists them — the lighting contract's (`--lights`,
/// `--shadows`, `--shadow-map-size`, `--shadow-bias`: every method lights and shadows through
/// the contract's WGSL, [`crate::lighting`]). A method that reads mirror textures adds
/// `; mirror_textures` for the options every such method shares: the uneven-mirror tricks
/// ([`crate::uneven`]) and `--stereo-mirrors` ([`crate::stereo_mirrors`]).
#[macro_export]
macro_rules! method_options {
    ($($own:expr),* $(,)?) => {
        &[
            $($own,)*
            &$crate::lighting::LIGHTS,
            &$crate::lighting::SHADOWS,
            &$crate::lighting::SHADOW_MAP_SIZE,
            &$crate::lighting::SHADOW_BIAS,
        ]
    };
    ($($own:expr),* ; mirror_textures) => {
        &[
            $($own,)*
            &$crate::lighting::LIGHTS,
            &$crate::lighting::SHADOWS,
            &$crate::lighting::SHADOW_MAP_SIZE,
            &$crate::lighting::SHADOW_BIAS,
            $crate::uneven::OPTIONS[0],
            $crate::uneven::OPTIONS[1],
            $crate::uneven::OPTIONS[2],
            $crate::uneven::OPTIONS[3],
            $crate::uneven::OPTIONS[4],
            &$crate::stereo_mirrors::STEREO_MIRRORS,
        ]
    };
}
