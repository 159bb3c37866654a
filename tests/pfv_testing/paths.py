"""Where the repository's folders are, seen from this package (build/python/pfv_testing is a link to
tests/pfv_testing, resolved here, so the paths are those of the source tree)."""
import os

PACKAGE = os.path.dirname(os.path.realpath(__file__))
REPO = os.path.dirname(os.path.dirname(PACKAGE))
BENCH = os.path.join(REPO, 'bench')
EXAMPLES = os.path.join(REPO, 'examples')
TEST_DATA = os.path.join(REPO, 'tests', 'data')
PACKINGS = os.path.join(TEST_DATA, 'packings')  # shipped packings, bit-identical on every machine


def example(name):
    """The path of examples/<name>."""
    return os.path.join(EXAMPLES, name)


def tool(name):
    """The path of a script of this package that YADE runs by path (yade-double -x), e.g. run_yade_script.py."""
    return os.path.join(PACKAGE, name)
