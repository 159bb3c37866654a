# Run by CTest in place of a lint test whose tool was not found when the build was configured: a
# missing linter fails the test, naming what to install, rather than leaving the check out.
message(FATAL_ERROR "${PFV_LINT_MISSING}")
