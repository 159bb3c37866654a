"""Options of the benchmark programs, `--name=value` on the command line."""


def option(argv, name, default):
    """The value of --name=VALUE in argv, converted to the type of `default` (an int accepts 1e6), else `default`.
    A bool default is True when the bare flag --name is given."""
    for a in argv:
        if isinstance(default, bool) and a == '--' + name:
            return True
        if a.startswith('--' + name + '='):
            value = a.split('=', 1)[1]
            if default is None or isinstance(default, str):
                return value
            if isinstance(default, bool):
                return bool(value)
            if isinstance(default, int):
                return int(float(value))
            return type(default)(value)
    return default
