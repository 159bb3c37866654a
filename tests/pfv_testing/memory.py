"""This process's memory from /proc (Linux): current and peak resident set, and the reset of the peak."""


def rss_kb(field="VmRSS"):
    """A field of /proc/self/status in kB: VmRSS (resident now) or VmHWM (peak since start or the last reset)."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    return -1


def reset_peak():
    """Resets VmHWM to the current RSS (writing 5 to /proc/self/clear_refs); False where the kernel refuses."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False
