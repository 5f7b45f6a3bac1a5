"""The package as a whole: its import layering and top-level exports, the
README's examples."""
