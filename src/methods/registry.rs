//! What one line of the registry (the `methods!` list in `mod.rs`) makes:
//! the `MethodConfig` enum (a variant per config), `METHOD_NAMES`,
//! `From<Config> for MethodConfig`, the string form's lookup and the
//! dispatch of every `MethodConfig` method to the config's `MethodSpec`
//! (its own module), the capabilities rows in the list's order; and for a
//! line that names its kernel (`Config => Kernel`), the `Method` variant
//! that a resolved config runs and the dispatch of every `Method` method
//! to the kernel's `Kernel` (`kernel.rs`, also in the method's module).
//!
//! A macro, not a trait object: `MethodConfig` stays a plain `Copy + Eq +
//! Hash` enum that the stages match on. It names only `config.rs` (the
//! shared trait and types); the configs' modules never name it back (a
//! resolution returns `MethodSpec::Resolved`, turned into a `MethodConfig`
//! here), so no file imports itself through another.

/// The registry of method configs; see the module's doc. Invoked once, in
/// `mod.rs`, where each method's module is declared.
macro_rules! methods {
    ($($(#[doc = $doc:literal])* $variant:ident($config:ty $(=> $kernel:ty)? $(, $kw:ident)?),)*) => {
        /// What a user picks: a method with its options, or `Auto` (see
        /// `AutoConfig`).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum MethodConfig {
            $($(#[doc = $doc])* $variant($config),)*
        }

        /// A method's kernel, with the options that change what it computes
        /// (the options that change what it reads, layers and their
        /// resolution, are the pipeline's: see `config.rs`): what a
        /// resolved config runs (`MethodConfig::kernel`), one variant per
        /// registry line that names a kernel. The stages ask it through
        /// `Kernel` (`kernel.rs`), never by its variant.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum Method {
            $($(
                #[doc = concat!("The kernel of `", stringify!($config), "`.")]
                $variant($kernel),
            )?)*
        }

        $($(impl From<$kernel> for Method {
            fn from(k: $kernel) -> Self {
                Method::$variant(k)
            }
        })?)*

        impl Method {
            /// The name a user passes as `method=`.
            pub fn name(&self) -> &'static str {
                use $crate::methods::config::MethodSpec;
                match self {
                    $($(Method::$variant(k) => {
                        let _: &$kernel = k;
                        <$config as MethodSpec>::NAME
                    })?)*
                }
            }

            /// What the method reads of the occluders (`Kernel::READS`).
            pub fn reads(&self) -> &'static [$crate::methods::Input] {
                use $crate::methods::kernel::Kernel;
                match self {
                    $($(Method::$variant(_) => <$kernel as Kernel>::READS,)?)*
                }
            }

            /// `Kernel::TESTS_PLANES`.
            pub fn tests_planes(&self) -> bool {
                use $crate::methods::kernel::Kernel;
                match self {
                    $($(Method::$variant(_) => <$kernel as Kernel>::TESTS_PLANES,)?)*
                }
            }

            /// `Kernel::READS_EVERY_FACE`.
            pub fn reads_every_face(&self) -> bool {
                use $crate::methods::kernel::Kernel;
                match self {
                    $($(Method::$variant(_) => <$kernel as Kernel>::READS_EVERY_FACE,)?)*
                }
            }

            /// f32 maps the kernel keeps per occluder layer
            /// (`Kernel::maps_per_layer`).
            pub fn kernel_maps_per_layer(&self) -> usize {
                use $crate::methods::kernel::Kernel;
                match self {
                    $($(Method::$variant(k) => <$kernel as Kernel>::maps_per_layer(k),)?)*
                }
            }

            /// `Kernel::visit_cost`: `None` for a kernel that does not
            /// gather over the occluder maps.
            pub fn visit_cost(&self) -> Option<f64> {
                use $crate::methods::kernel::Kernel;
                match self {
                    $($(Method::$variant(k) => <$kernel as Kernel>::visit_cost(k),)?)*
                }
            }

            /// `Kernel::rays`: the light samples a receiver, the probe's
            /// and the engine of a ray-traced kernel.
            pub fn rays(&self) -> Option<(u32, Option<u32>, $crate::methods::engine::Engine)> {
                use $crate::methods::kernel::Kernel;
                match self {
                    $($(Method::$variant(k) => <$kernel as Kernel>::rays(k),)?)*
                }
            }

            /// `Kernel::check_cost`.
            pub fn check_cost(
                &self,
                inputs: &$crate::methods::ShadowInputs,
                points: Option<&[$crate::methods::LightPoint]>,
            ) -> $crate::error::Result<()> {
                use $crate::methods::kernel::Kernel;
                match self {
                    $($(Method::$variant(k) => <$kernel as Kernel>::check_cost(k, inputs, points),)?)*
                }
            }

            /// The CPU implementation.
            pub fn implementation(&self) -> Box<dyn $crate::methods::ShadowMethod> {
                use $crate::methods::kernel::Kernel;
                match self {
                    $($(Method::$variant(k) => <$kernel as Kernel>::implementation(k),)?)*
                }
            }
        }

        /// The method names a user can pass as `method=`, in the table's order.
        pub const METHOD_NAMES: &[&str] =
            &[$(<$config as $crate::methods::config::MethodSpec>::NAME),*];

        $(impl From<$config> for MethodConfig {
            fn from(c: $config) -> Self {
                MethodConfig::$variant(c)
            }
        })*

        impl MethodConfig {
            /// The config named `name` with the loose options given: each
            /// must apply to that method.
            pub fn from_name(
                name: &str,
                o: &$crate::methods::config::LooseOptions,
            ) -> $crate::error::Result<Self> {
                use $crate::methods::config::MethodSpec;
                let refuse = |opt: &str, applies: &str| {
                    $crate::error::Error::invalid(
                        opt,
                        format!("applies to {applies}, not to {name:?}"),
                    )
                };
                $(if name == <$config as MethodSpec>::NAME {
                    return Ok(MethodConfig::$variant(<$config>::from_loose(o, &refuse)?));
                })*
                Err($crate::error::Error::invalid(
                    "method",
                    format!("unknown method {name:?}; available: {METHOD_NAMES:?}"),
                ))
            }

            /// A typed config passed with loose options too: refused (one
            /// place says each option).
            pub fn refuse_loose(
                o: &$crate::methods::config::LooseOptions,
            ) -> $crate::error::Result<()> {
                match o.given().first() {
                    None => Ok(()),
                    Some(opt) => Err($crate::error::Error::invalid(
                        *opt,
                        "give it inside the method config (for example \
                         method=Bitmask(samples=64)), not beside it",
                    )),
                }
            }

            /// The name a user passes as `method=`.
            pub fn name(&self) -> &'static str {
                use $crate::methods::config::MethodSpec;
                match self {
                    $(MethodConfig::$variant(_) => <$config as MethodSpec>::NAME,)*
                }
            }

            /// The config that runs for `ctx` (`MethodSpec::resolve`).
            pub fn resolve(
                &self,
                ctx: &$crate::methods::config::CallContext,
            ) -> $crate::error::Result<MethodConfig> {
                use $crate::methods::config::MethodSpec;
                match *self {
                    $(MethodConfig::$variant(c) => c.resolve(ctx).map(MethodConfig::from),)*
                }
            }

            /// Occluder layers of a resolved config (0 for methods that read none).
            pub fn passes(&self) -> u32 {
                use $crate::methods::config::MethodSpec;
                match self {
                    $(MethodConfig::$variant(c) => c.passes(),)*
                }
            }

            /// Occluder maps' (W, H) of a resolved config (None for methods
            /// that read no maps).
            pub fn occluder_resolution(&self) -> Option<(usize, usize)> {
                use $crate::methods::config::MethodSpec;
                match self {
                    $(MethodConfig::$variant(c) => c.occluder_resolution(),)*
                }
            }

            /// The config named `name` from its keyword form (`Bitmask(samples=64)`,
            /// `keywords.rs`): each option given must be the method's.
            pub fn from_keywords(
                name: &str,
                k: &$crate::methods::keywords::Keywords,
            ) -> $crate::error::Result<Self> {
                #[allow(unused_imports)]
                use $crate::methods::config::MethodSpec;
                #[allow(unused_imports)]
                use $crate::methods::keywords::KeywordForm;
                $($crate::methods::registry::with_keywords!($($kw)? ; {
                    if name == <$config as MethodSpec>::NAME {
                        k.check_names(&<$config as MethodSpec>::info())?;
                        return Ok(MethodConfig::$variant(<$config>::from_keywords(k)?));
                    }
                } ; {});)*
                Err($crate::error::Error::invalid(
                    "method",
                    format!("{name:?} has no keyword form (its class is the bindings' own)"),
                ))
            }

            /// The config's options as its keyword form takes them, in its
            /// table's order; `None` for a config without a keyword form.
            pub fn keywords(
                &self,
            ) -> Option<Vec<(&'static str, $crate::methods::info::Value)>> {
                #[allow(unused_imports)]
                use $crate::methods::keywords::KeywordForm;
                match self {
                    $(#[allow(unused_variables)] MethodConfig::$variant(c) => {
                        $crate::methods::registry::with_keywords!($($kw)? ; {
                            Some(c.keywords())
                        } ; { None })
                    })*
                }
            }

            /// The names of the methods whose config has a keyword form.
            pub fn keyword_forms() -> Vec<&'static str> {
                let marked = [$($crate::methods::registry::with_keywords!($($kw)? ; {
                    true
                } ; { false })),*];
                METHOD_NAMES
                    .iter()
                    .zip(marked)
                    .filter_map(|(name, k)| k.then_some(*name))
                    .collect()
            }

            /// The kernel of a config (`MethodSpec::kernel`); resolve it
            /// first for the backend's defaults.
            pub fn kernel(&self) -> Method {
                use $crate::methods::config::MethodSpec;
                match self {
                    $(MethodConfig::$variant(c) => Method::from(c.kernel()),)*
                }
            }

            /// Every method's row of `capabilities()`, in the registry's order.
            pub fn infos() -> Vec<$crate::methods::info::MethodInfo> {
                use $crate::methods::config::MethodSpec;
                vec![$(<$config as MethodSpec>::info()),*]
            }
        }
    };
}

pub(crate) use methods;

/// `with_keywords!(keywords ; { then } ; { otherwise })`: `then` for a
/// registry line marked `keywords`, `otherwise` for one that is not.
macro_rules! with_keywords {
    (keywords ; { $($then:tt)* } ; { $($otherwise:tt)* }) => {
        $($then)*
    };
    (; { $($then:tt)* } ; { $($otherwise:tt)* }) => {
        $($otherwise)*
    };
}

pub(crate) use with_keywords;

#[cfg(test)]
mod tests {
    use crate::backend::Backend;
    use crate::error::Error;
    use crate::methods::config::{CallContext, LooseOptions};
    use crate::methods::{bitmask, AutoConfig, BitmaskConfig, BitmaskKernel, Method, MethodConfig};

    fn cpu(resolution: (usize, usize)) -> CallContext {
        CallContext {
            backend: Backend::Cpu,
            resolution,
            depth_layers: None,
            eye: false,
        }
    }

    #[test]
    fn auto_is_ssm_with_quarter_occluder_maps_at_least_64() {
        let r = MethodConfig::Auto(AutoConfig::default())
            .resolve(&cpu((512, 100)))
            .unwrap();
        assert_eq!(r.occluder_resolution(), Some((128, 64)));
        assert_eq!(r.passes(), 2);
        let r = MethodConfig::Auto(AutoConfig::default())
            .resolve(&cpu((40, 40)))
            .unwrap();
        assert_eq!(r.occluder_resolution(), Some((40, 40)));
    }

    #[test]
    fn defaults_depend_on_the_backend_and_the_entry() {
        let b = MethodConfig::Bitmask(BitmaskConfig::default());
        assert_eq!(
            b.resolve(&cpu((8, 8))).unwrap().kernel(),
            Method::Bitmask(BitmaskKernel {
                samples: 256,
                hierarchy: true,
                gaps: bitmask::Gaps::Closed,
            })
        );
        let gpu = CallContext {
            backend: Backend::Gpu,
            ..cpu((8, 8))
        };
        assert_eq!(
            b.resolve(&gpu).unwrap().kernel(),
            Method::Bitmask(BitmaskKernel {
                samples: 256,
                hierarchy: false,
                gaps: bitmask::Gaps::Closed,
            })
        );
        let depth = CallContext {
            depth_layers: Some((1, (4, 4))),
            ..cpu((8, 8))
        };
        let r = b.resolve(&depth).unwrap();
        assert_eq!((r.passes(), r.occluder_resolution()), (1, Some((4, 4))));
        let three =
            MethodConfig::Bitmask(BitmaskConfig::new(None, Some(3), None, None, None).unwrap());
        assert!(
            matches!(three.resolve(&depth), Err(Error::InvalidArgument { ref arg, .. }) if arg == "passes")
        );
    }

    #[test]
    fn a_keyword_form_names_its_table_s_options_in_order_and_reads_back() {
        use crate::methods::keywords::{Given, Keywords};
        let forms = MethodConfig::keyword_forms();
        assert!(forms.contains(&"bitmask") && !forms.contains(&"auto"));
        for info in MethodConfig::infos() {
            let Ok(c) = MethodConfig::from_keywords(info.name, &Keywords::default()) else {
                assert!(!forms.contains(&info.name), "{}", info.name);
                assert!(MethodConfig::Auto(AutoConfig::default())
                    .keywords()
                    .is_none());
                continue;
            };
            let values = c.keywords().unwrap();
            let names: Vec<&str> = values.iter().map(|(n, _)| *n).collect();
            let table: Vec<&str> = info.options.iter().map(|o| o.name).collect();
            assert_eq!(names, table, "{}", info.name);
            let again = MethodConfig::from_keywords(info.name, &Keywords::of(&values)).unwrap();
            assert_eq!(again, c, "{}", info.name);
        }
        let given = Keywords(vec![
            ("samples".into(), Given::Int(64)),
            ("occluder_resolution".into(), Given::Resolution((32, 16))),
            ("gaps".into(), Given::Str("open".into())),
        ]);
        let c = MethodConfig::from_keywords("bitmask", &given).unwrap();
        assert_eq!(
            MethodConfig::from_keywords("bitmask", &Keywords::of(&c.keywords().unwrap())).unwrap(),
            c
        );
        let MethodConfig::Bitmask(b) = c else {
            panic!("{c:?}")
        };
        assert_eq!((b.samples, b.occluder_resolution), (64, Some((32, 16))));
        let e = MethodConfig::from_keywords(
            "exact",
            &Keywords(vec![("gaps".into(), Given::Str("open".into()))]),
        )
        .unwrap_err();
        assert!(matches!(e, Error::InvalidArgument { ref arg, .. } if arg == "gaps"));
        let e = MethodConfig::from_keywords(
            "exact",
            &Keywords(vec![("samples".into(), Given::Str("x".into()))]),
        )
        .unwrap_err();
        assert!(matches!(e, Error::InvalidArgument { ref arg, .. } if arg == "samples"));
    }

    #[test]
    fn options_that_do_not_apply_are_refused_by_name() {
        let o = LooseOptions {
            samples: Some(64),
            ..Default::default()
        };
        let e = MethodConfig::from_name("ssm", &o).unwrap_err();
        assert!(matches!(e, Error::InvalidArgument { ref arg, .. } if arg == "samples"));
        let o = LooseOptions {
            hierarchy: Some(true),
            ..Default::default()
        };
        let e = MethodConfig::from_name("exact", &o).unwrap_err();
        assert!(matches!(e, Error::InvalidArgument { ref arg, .. } if arg == "hierarchy"));
        assert!(MethodConfig::refuse_loose(&o).is_err());
    }
}
