# Filled in by the work on neuflowd (e2e).
