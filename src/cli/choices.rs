//! Command-line mirrors of the library's enums that flags take (`--blend`, `--weights`, …).
//!
//! The library derives no clap trait: each mirror here derives [`clap::ValueEnum`] with the
//! library variant's name and doc comment (which clap shows as the value's help), and converts
//! both ways with exhaustive matches, so a variant added to the library and not here does not
//! compile. Flags keep the library type as their value through [`parser`], and take their
//! default from the library through [`default_name!`], so no flag restates a default.

use clap::builder::{EnumValueParser, TypedValueParser};
use clap::ValueEnum;
use sinew::autorig::TemplateChoice;
use sinew::colorize::{ColorWeights, FillMode, RegionSplit};
use sinew::export::spine::{BakeMode, SpinePreset};
use sinew::schema::SchemaKind;
use sinew::skin::Blend;
use sinew::weights::WeightMethod;

/// A value parser for library enum `L` through its mirror `A`: `A`'s names and help, `L`'s
/// value.
pub fn parser<A, L>() -> impl TypedValueParser<Value = L>
where
    A: ValueEnum + Clone + Send + Sync + 'static,
    L: From<A> + Clone + Send + Sync + 'static,
{
    EnumValueParser::<A>::new().map(L::from)
}

/// The flag value naming library value `$value` through its mirror `$mirror`, as a
/// `&'static str` for clap's `default_value`: `default_value = default_name!(FillModeArg,
/// ColorizeOptions::default().fill)` shows and parses the library's default, whatever it
/// becomes. Worked out once per call site.
macro_rules! default_name {
    ($mirror:ty, $value:expr) => {{
        static NAME: std::sync::OnceLock<String> = std::sync::OnceLock::new();
        NAME.get_or_init(|| {
            clap::ValueEnum::to_possible_value(&<$mirror>::from($value))
                .expect("mirrors hide no value")
                .get_name()
                .to_owned()
        })
        .as_str()
    }};
}
pub(crate) use default_name;

macro_rules! mirror {
    ($mirror:ident => $library:ident { $($(#[$doc:meta])* $variant:ident,)* }) => {
        #[doc = concat!("[`", stringify!($library), "`] on the command line.")]
        #[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
        pub enum $mirror {
            $($(#[$doc])* $variant,)*
        }

        impl From<$mirror> for $library {
            fn from(value: $mirror) -> $library {
                match value {
                    $($mirror::$variant => $library::$variant,)*
                }
            }
        }

        impl From<$library> for $mirror {
            fn from(value: $library) -> $mirror {
                match value {
                    $($library::$variant => $mirror::$variant,)*
                }
            }
        }
    };
}

mirror!(BlendArg => Blend {
    /// Linear blend skinning: fast, exact for affine handles; joints thin when twisted far.
    Linear,
    /// Dual-quaternion skinning: keeps limbs' thickness at strongly rotated joints.
    Dqs,
    /// Linear blending with stretchable bones: a bone scaled along its length stretches its
    /// limb and carries what lies past its tail.
    Stretch,
});

mirror!(WeightMethodArg => WeightMethod {
    /// Bounded biharmonic weights (Jacobson et al. 2011): smooth, local, in [0, 1].
    Bbw,
    /// Harmonic weights: fast, in [0, 1], but with a kink at point handles.
    Harmonic,
    /// Unconstrained biharmonic weights: smooth but not bounded nor local (for comparison).
    Biharmonic,
    /// Rigid cutout weights: the nearest handle inside the shape, blended over
    /// `--blend PX` around joints.
    Rigid,
});

mirror!(BakeModeArg => BakeMode {
    /// Only what native timelines cannot express (default).
    Auto,
    /// Every bone, at the bake rate (for engines that resample anyway, and to test baking).
    All,
});

mirror!(SpinePresetArg => SpinePreset {
    /// Every vertex and influence: plays exactly what sinew draws (default).
    Full,
    /// For games: at most 250 vertices per part and 4 influences per vertex.
    Game,
});

mirror!(TemplateArg => TemplateChoice {
    /// The template the layer names or the drawing suggest, or none; says which and why.
    Auto,
    /// No template: bones from the medial axis, or one per layer named after it.
    None,
    /// Spine (hip, chest), head, two arms and two legs of two bones each.
    Humanoid,
    /// Spine (hip, chest), head, a tail of two bones and four legs of two bones each.
    Quadruped,
});

mirror!(FillModeArg => FillMode {
    /// Each pixel its color: crisp cartoon fills.
    Flat,
    /// Region edges antialiased: each color's share of a small box around the pixel.
    Soft,
});

mirror!(RegionSplitArg => RegionSplit {
    /// Scaled geodesic reach: colors meet at necks, and each scribble reaches in
    /// proportion to its size.
    Reach,
    /// An ink-density flood: boundaries where ink crowds (G'MIC Smart Coloring's order).
    Density,
    /// A depth flood: boundaries where the region is narrowest; a scribble in the middle
    /// claims more than one in a corner.
    Depth,
    /// The content-aware (5D-lifted) weights decide.
    Weights,
});

mirror!(SchemaKindArg => SchemaKind {
    /// The handles file (`sinew rig --handles`, `sinew autorig -o`).
    Handles,
    /// The rig document (`sinew rig -o`, the editor's documents).
    Rig,
    /// The pose file (`sinew pose --pose`).
    Pose,
    /// An animations file: animation name → animation, as the rig document's `animations`.
    Animations,
    /// The scribbles JSON of `sinew colorize --scribbles`.
    Scribbles,
    /// An events file: event name → definition, as the rig document's `events`.
    Events,
    /// The batch manifest of `sinew batch`.
    Batch,
});

mirror!(ColorWeightsArg => ColorWeights {
    /// Harmonic weights: one Laplace solve per color over one factorization. Fast.
    Harmonic,
    /// Bounded biharmonic weights (Jacobson et al. 2011): smoother blends, far slower.
    Bbw,
});

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Serialize;

    /// Every mirror value converts to the library value whose file name (serde) is the flag
    /// value's name, and back to itself.
    fn check<A, L>()
    where
        A: ValueEnum + Copy + PartialEq + std::fmt::Debug + From<L>,
        L: From<A> + Serialize + Copy,
    {
        for &value in A::value_variants() {
            let name = value.to_possible_value().expect("no hidden values");
            let library = L::from(value);
            assert_eq!(
                serde_json::to_value(library).expect("serializes"),
                serde_json::Value::String(name.get_name().to_string())
            );
            assert_eq!(A::from(library), value);
        }
    }

    #[test]
    fn mirrors_name_the_library_values_as_files_do() {
        check::<BlendArg, Blend>();
        check::<WeightMethodArg, WeightMethod>();
        check::<BakeModeArg, BakeMode>();
        check::<SpinePresetArg, SpinePreset>();
        check::<TemplateArg, TemplateChoice>();
        check::<FillModeArg, FillMode>();
        check::<ColorWeightsArg, ColorWeights>();
        check::<RegionSplitArg, RegionSplit>();
        for &kind in SchemaKindArg::value_variants() {
            let name = kind.to_possible_value().expect("no hidden values");
            assert_eq!(SchemaKind::from(kind).name(), name.get_name());
            assert_eq!(SchemaKindArg::from(SchemaKind::from(kind)), kind);
        }
    }

    /// Parses `sinew ARGS`.
    fn parse(args: &[&str]) -> crate::cli::Command {
        use clap::Parser;
        let argv = std::iter::once("sinew").chain(args.iter().copied());
        crate::cli::Cli::try_parse_from(argv)
            .unwrap_or_else(|e| panic!("{args:?}: {e}"))
            .command
    }

    #[test]
    fn flags_left_out_take_the_library_defaults() {
        use crate::cli::{Command, ExportFormat};
        use sinew::colorize::ColorizeOptions;
        use sinew::export::spine::{SpineOptions, SpineVersion};
        use sinew::io::BuildOptions;
        use sinew::playback::RenderSettings;

        let Command::Colorize(a) =
            parse(&["colorize", "a.png", "--scribbles", "s.json", "-o", "o.png"])
        else {
            panic!("not colorize")
        };
        let d = ColorizeOptions::default();
        assert_eq!((a.fill, a.weights, a.split), (d.fill, d.weights, d.split));
        assert_eq!(
            [
                a.scale,
                a.gap_closing,
                a.split_depth,
                a.split_exponent,
                a.split_blur
            ],
            [
                d.scale,
                d.gap_closing_px,
                d.split_depth_px,
                d.split_depth_exponent,
                d.split_blur_px
            ]
        );
        assert_eq!(
            [a.join_curve, a.join_segment],
            [
                d.end_point_join.spline_max_px,
                d.end_point_join.segment_max_px
            ]
        );

        let Command::Export(export) = parse(&["export", "spine", "rig.json", "-o", "out"]) else {
            panic!("not export")
        };
        let ExportFormat::Spine(a) = export.format else {
            panic!("not spine")
        };
        let d = SpineOptions::default();
        assert_eq!(
            (a.preset, a.bake, a.fps),
            (SpinePreset::default(), d.bake, d.bake_fps)
        );
        assert_eq!(SpineVersion::parse(&a.spine_version).ok(), Some(d.version));

        let Command::Export(export) = parse(&["export", "gltf", "rig.json", "-o", "o.glb"]) else {
            panic!("not export")
        };
        let ExportFormat::Gltf(a) = export.format else {
            panic!("not gltf")
        };
        let d = sinew::export::gltf::GltfOptions::default();
        assert_eq!(
            (a.fps, a.px_per_unit, a.layer_spacing),
            (d.bake_fps, d.px_per_unit, d.layer_spacing)
        );

        let Command::Render(a) = parse(&["render", "rig.json", "--anim", "walk", "-o", "o.gif"])
        else {
            panic!("not render")
        };
        let d = RenderSettings::default();
        assert_eq!((a.blend, a.fps, a.scale), (d.blend, d.fps, d.scale));
        assert_eq!(
            SpineVersion::parse(&a.spine_version).ok(),
            Some(d.export.version)
        );
        assert_eq!(a.bake_fps, d.export.bake_fps);

        let Command::Pose(a) = parse(&["pose", "rig.json"]) else {
            panic!("not pose")
        };
        assert_eq!(a.blend, Blend::default());
        assert_eq!(
            SpineVersion::parse(&a.spine_version).ok(),
            Some(SpineVersion::default())
        );
        assert_eq!(a.bake_fps, SpineOptions::default().bake_fps);

        let Command::Rig(a) = parse(&["rig", "a.png", "-o", "rig.json"]) else {
            panic!("not rig")
        };
        assert_eq!(a.build.options(), BuildOptions::default());
    }
}
