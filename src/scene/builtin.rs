//! Scenes shipped with the program, selected by name instead of a file path. Their TOML sources
//! live next to this file so that users can copy one as a starting point.

/// `(name, TOML text)` of every built-in scene.
pub const BUILTINS: &[(&str, &str)] = &[
    ("cantilever", include_str!("builtin/cantilever.toml")),
    (
        "footing-shallow",
        include_str!("builtin/footing-shallow.toml"),
    ),
    (
        "block-compression",
        include_str!("builtin/block-compression.toml"),
    ),
    ("footing", include_str!("builtin/footing.toml")),
    ("tbar-smooth", include_str!("builtin/tbar-smooth.toml")),
    ("tbar-rough", include_str!("builtin/tbar-rough.toml")),
    (
        "tbar-softening",
        include_str!("builtin/tbar-softening.toml"),
    ),
    ("pipeline", include_str!("builtin/pipeline.toml")),
    ("vertical-cut", include_str!("builtin/vertical-cut.toml")),
    (
        "footing-layered",
        include_str!("builtin/footing-layered.toml"),
    ),
    (
        "footing-gradient",
        include_str!("builtin/footing-gradient.toml"),
    ),
    (
        "circular-footing",
        include_str!("builtin/circular-footing.toml"),
    ),
    ("ball", include_str!("builtin/ball.toml")),
    ("spudcan", include_str!("builtin/spudcan.toml")),
    ("cpt", include_str!("builtin/cpt.toml")),
    (
        "footing-mohr-coulomb",
        include_str!("builtin/footing-mohr-coulomb.toml"),
    ),
];

/// TOML text of the built-in scene `name`.
pub fn builtin(name: &str) -> Option<&'static str> {
    BUILTINS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, text)| *text)
}

/// Names of the built-in scenes, comma separated, for error messages and help.
pub fn builtin_names() -> String {
    BUILTINS
        .iter()
        .map(|(n, _)| *n)
        .collect::<Vec<_>>()
        .join(", ")
}
