"""The pass/fail plumbing of the YADE tests: each named check prints an "ok" or a "FAIL" line, and `report` ends the
script with the exit code CTest reads (0 all passed, 1 some failed, SKIPPED when the test cannot run here)."""
import sys

# CTest's SKIP_RETURN_CODE for the YADE tests (tests/CMakeLists.txt): a tool the test needs is missing.
SKIPPED = 77

failures = []


def fail(text):
    print("FAIL " + text, flush=True)
    failures.append(text)


def check(what, ok, detail=""):
    """Record the check `what`; `detail` (measured values, tolerances) follows it on its line. Returns `ok`."""
    if ok:
        print(f"ok   {what} {detail}", flush=True)
    else:
        fail(f"{what} {detail}")
    return ok


def expect_error(what, kind, fragment, action, ignore_case=True):
    """`action` raises `kind` with `fragment` in its message (ignoring case unless told not to)."""
    try:
        action()
    except kind as error:
        message = str(error)
        if not (fragment.lower() in message.lower() if ignore_case else fragment in message):
            fail(f"{what}: message lacks '{fragment}': {error}")
        else:
            print(f"ok   {what}: {type(error).__name__}: {str(error).splitlines()[-1][:120]}")
        return
    except Exception as error:  # noqa: BLE001
        fail(f"{what}: expected {kind.__name__}, got {type(error).__name__}: {error}")
        return
    fail(f"{what}: no error raised")


def report(name):
    """Print the summary of the `name` checks and exit 0 if all passed, 1 if any failed."""
    if failures:
        print(f"{len(failures)} {name} checks failed")
        sys.exit(1)
    print(f"all {name} checks passed")
    sys.exit(0)


def skip(reason):
    """End the test as skipped: what it needs is missing here."""
    print("SKIP " + reason)
    sys.exit(SKIPPED)
