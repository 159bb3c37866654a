"""What the report says of the machine and the software a run measured."""
import os
import platform
import subprocess
import sys

from pfv_testing.paths import REPO


def sh(cmd):
    try:
        return subprocess.run(cmd, shell=True, capture_output=True, text=True, timeout=20).stdout.strip()
    except Exception:
        return ''


def machine_description():
    import yade

    d = {}
    lscpu = sh('lscpu')
    for key in (
        'Model name',
        'CPU(s)',
        'Thread(s) per core',
        'Core(s) per socket',
        'Socket(s)',
        'Hypervisor vendor',
        'L2 cache',
        'L3 cache',
        'CPU max MHz',
        'BogoMIPS',
    ):
        for line in lscpu.splitlines():
            if line.startswith(key + ':'):
                d[key] = line.split(':', 1)[1].strip()
    mem = sh("grep MemTotal /proc/meminfo").split()
    d['RAM'] = '%.1f GiB' % (int(mem[1]) / 2**20) if len(mem) > 1 else '?'
    d['kernel'] = platform.release()
    d['os'] = sh('. /etc/os-release && echo "$PRETTY_NAME"')
    d['compiler'] = sh('c++ --version | head -1')
    cache = os.path.join(REPO, 'build', 'CMakeCache.txt')
    flags = []
    if os.path.exists(cache):
        for line in open(cache):
            for key in ('CMAKE_BUILD_TYPE:', 'CMAKE_CXX_FLAGS_RELEASE:', 'CMAKE_CXX_FLAGS:', 'OpenMP_CXX_FLAGS:'):
                if line.startswith(key):
                    flags.append('%s=%s' % (key.split(':')[0], line.split('=', 1)[1].strip()))
    d['pfv build'] = ', '.join(flags)
    pkgs = sh(
        "dpkg-query -W -f='${Package} ${Version}\\n' yade libcgal-dev libsuitesparse-dev libmetis-dev "
        "libeigen3-dev pybind11-dev python3-numpy libboost-dev 2>/dev/null"
    )
    d['packages'] = '; '.join(pkgs.splitlines())
    d['python'] = platform.python_version()
    d['yade'] = getattr(yade.config, 'version', '?') if hasattr(yade, 'config') else '?'
    try:
        import pfv

        d['pfv module'] = os.path.dirname(pfv.__file__)
    except Exception as e:
        d['pfv module'] = 'IMPORT FAILED: %s' % e
    d['git'] = sh('git -C %s rev-parse --short HEAD' % REPO) + (
        ' (working tree modified in lib/ pkg/)'
        if sh('git -C %s status --porcelain lib pkg CMakeLists.txt' % REPO)
        else ''
    )
    d['BLAS'] = (
        os.path.realpath('/usr/lib/x86_64-linux-gnu/libblas.so.3')
        + ' (children run with OPENBLAS_NUM_THREADS = OMP_NUM_THREADS = yade -jN)'
    )
    d['load average at start'] = ' '.join('%.2f' % x for x in os.getloadavg())
    return d


def pfv_fingerprint():
    """Where the pfv extension module loaded by this process lives and when it was built: colleagues may reinstall
    pfv while a long benchmark runs; the driver reports it if its children did not all use the same build."""
    mod = sys.modules.get('pfv._core')
    if mod is None:
        return None
    return getattr(mod, '__file__', '?')
