//! The fixed-α solver (SPEC §5): semi-smooth Newton with a line search, and projected
//! block Gauss–Seidel as a fallback.
