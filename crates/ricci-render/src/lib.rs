//! Pictures for ricci: a small software renderer (PNG), 2D plots (SVG/PNG), glTF export.
