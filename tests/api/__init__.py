"""The calls' contracts (softshadow.api): the entry points and their results, bad
input at every public entry, thread safety, the lights, results shown in a
notebook, and output files (softshadow.io)."""
