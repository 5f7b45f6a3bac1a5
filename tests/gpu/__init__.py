"""The GPU backend against the CPU one, light view and eye view (lavapipe in CI;
SOFTSHADOW_REQUIRE_GPU=1 makes a missing adapter a failure)."""
