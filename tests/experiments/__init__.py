"""The research commands (softshadow.experiments): the study and the demo."""
