"""The small items issue 26's last sweep left (doors15a), one regression test each; each
failed on the code before its fix.

* a number of hundreds of digits (1e300 on an integer key is the integer 10**300) was printed
  whole in its one-line message; now it is shortened (1e+300) in every config message;
"""

import re
import tomllib
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from oneline import one_line, python_lines
from scipy import sparse, stats
from scipy.special import gammaln

from sim.cli import main
from sim.lsq.sparse import factorize
from sim.mc.config import ConfigError, shown
from sim.mc.runner import jackknife
from sim.studies import load_study
from sim.studies.network.estimates import _sums, mc_estimates, sample_sd

ROOT = Path(__file__).resolve().parent.parent
STUDIES = sorted((ROOT / "studies").glob("*.toml"))
#: one study file of each kind (the smallest: the schema is the kind's, the network is built)
KINDS = sorted(
    {
        tomllib.loads(f.read_text())["study"]: f
        for f in sorted(STUDIES, key=lambda f: -f.stat().st_size)
    }.values()
)
FIELD = ROOT / "studies" / "network_testfield.toml"
LONG = re.compile(r"\d{20,}")


def test_shown_shortens_only_numbers_longer_than_64_bits():
    assert shown(2**63 - 1) == "9223372036854775807"  # a legal seed stays whole
    assert shown(10**300) == "1e+300" and shown(-(10**30)) == "-1e+30"
    assert shown(10**400) == "a 401-digit number" and shown(1.5) == "1.5"
    assert shown(-(10**5000)) == "a negative number of over 4000 digits"
    msg = str(ConfigError("k", f"{10**40} at /tmp/{10**25}/x and 0.{10**30}"))
    assert msg.startswith("k: 1e+40 at /tmp/1") and f"0.{10**30}" in msg  # paths, decimals kept
    assert str(ConfigError("k", "x " + "7" * 5000)) == "k: x a 5000-digit number"  # > 4300


@pytest.mark.parametrize("path", KINDS, ids=lambda p: p.stem)
def test_a_huge_number_on_any_integer_key_gets_a_short_message(path):
    study, _ = load_study(path)
    ints = [k for k, f in study.schema.items() if f.kind in ("int", "list[int]")]
    assert ints, path
    for key in ints:
        kind = study.schema[key].kind
        for big in (1e300, -1e30, 1e30):
            value = [big] if kind == "list[int]" else big
            with pytest.raises(ConfigError) as err:
                load_study(path, values={key: value})
            msg = str(err.value)
            assert not LONG.search(msg) and len(msg) < 300, (key, msg)


@pytest.mark.parametrize(
    "setting, needle",
    [
        ("trials=1e300", "trials: must be <= 1e+07 (got 1e+300)"),
        ("seed=-1e30", "seed: must be >= 0 (got -1e+30)"),
        ("chunk=1e400", "chunk: 1e400 is beyond a 64-bit float's range"),  # doors29a
        ("trials=" + "1" * 401, "trials: an integer of 401 digits"),
        ('network.grids=[{prefix="N",nx=1e300,ny=3,spacing_m=25.0}]', "nx: 1e+300 x 3 points"),
        ('network.random=[{prefix="R",n=1e30,half_extent_mm=5.0}]', "network.random[0].n"),
    ],
)
def test_a_huge_set_override_gets_a_short_message(capsys, setting, needle):
    err = one_line(capsys, main(["check", str(FIELD), "--set", setting]), needle)
    assert not LONG.search(err) and len(err) < 300, err


def test_a_huge_nearest_is_every_target_in_the_work_estimate_too(capsys):
    """``nearest = 1e300`` builds every target (the build takes the smaller count); the work
    estimate multiplied by it and refused "9.06e+301 adjustments" naming no key."""

    def work(nearest: str) -> str:
        gen = f'[{{kind="distance",from="*",to="*",{nearest}sigma_mm=1.0}}]'
        assert main(["check", str(FIELD), "--set", f"network.generate={gen}"]) == 0
        (line,) = [x for x in capsys.readouterr().out.splitlines() if x.startswith("# work:")]
        return line

    every = work("")  # no nearest: every target
    assert work("nearest=1e300,") == every and "e+30" not in every, every


def _chunk_sums(rng, sig, trials=40, chunk=2):
    """The runner's per-chunk sums of ``trials`` normal errors of the sigmas ``sig`` (k, 2)."""
    C, k = trials // chunk, len(sig)
    e = rng.standard_normal((C, chunk, k, 2)) * sig
    return {
        "sum.n": np.full((C, 1), float(chunk)),
        "sum.e": e.sum(axis=1),
        "sum.ee": np.einsum("ctki,ctkj->ckij", e, e),
        "sum.inside": np.zeros((C, k)),
        "sum.reject": np.zeros((C, 1)),
    }


def test_the_sigma_ratio_is_unbiased_at_40_trials_and_its_interval_covers_1():
    """500 points of known sigmas, 40 trials in 20 chunks, 80 seeds: the new ratio's 95 %
    interval covers 1 as often as the binomial law allows and its mean is 1; the old mean of
    ``s / sigma`` sits at ``c4(40)`` (0.9936), 1.8 of its standard errors below 1."""
    k, seeds, n = 500, 80, 40
    sig = np.random.default_rng(5).uniform(0.5, 2.0, (k, 2))
    an = SimpleNamespace(cov=np.einsum("ki,ij->kij", sig**2, np.eye(2)))
    new, old = [], []
    for seed in range(seeds):
        sim = _chunk_sums(np.random.default_rng(seed), sig, n)
        new.append([r[0] for r in mc_estimates(an, list(range(k)), sim).ratio])

        def mean_sd(t):
            sd = sample_sd(t[0], t[1 : 1 + 2 * k], t[1 + 2 * k : 1 + 4 * k])
            return np.atleast_1d(np.mean(sd / sig.reshape(-1)))

        old.append([r[0] for r in jackknife(mean_sd, _sums(sim))])
    new, old = np.array(new), np.array(old)
    covers = int(((new[:, 1] <= 1) & (new[:, 2] >= 1)).sum())
    assert stats.binom.ppf(0.001, seeds, 0.95) <= covers, covers
    c4 = np.sqrt(2 / (n - 1)) * np.exp(gammaln(n / 2) - gammaln((n - 1) / 2))
    se = new[:, 0].std(ddof=1) / np.sqrt(seeds)  # of the mean over seeds (the old one's alike)
    assert abs(new[:, 0].mean() - 1) < 4 * se, (new[:, 0].mean(), se)
    assert abs(old[:, 0].mean() - c4) < 4 * se and 1 - old[:, 0].mean() > 10 * se
    assert int(((old[:, 1] <= 1) & (old[:, 2] >= 1)).sum()) < covers - 10  # the bias showed


def _chain(n: int = 200) -> list[str]:
    """``--set`` values of a chain of ``n`` points between two fixed ends on the x axis, each
    off the line by up to 1 mm, seen by the distances to its two nearest neighbours only."""
    rng = np.random.default_rng(3)
    pts = [
        '{name="A",x_m=0.0,y_m=0.0,role="fixed"}',
        f'{{name="B",x_m={n + 1}.0,y_m=0.0,role="fixed"}}',
    ]
    pts += [
        f'{{name="P{i}",x_m={i}.0,y_m={rng.uniform(-1e-3, 1e-3):.6f}}}' for i in range(1, n + 1)
    ]
    gen = '[{kind="distance",from="*",to="*",nearest=2,sigma_mm=1.0}]'
    sets = [f"network.points=[{','.join(pts)}]", "network.grids=[]", f"network.generate={gen}"]
    sets += ["network.observations=[]", "compare.fix=[]", "output.inner_over=[]"]
    return [a for v in sets for a in ("--set", v)]


def test_a_long_chain_nearly_in_line_names_its_weak_point_on_the_sparse_path(capsys):
    err = one_line(capsys, main(["check", str(FIELD), *_chain()]), "datum.kind", "singular")
    assert re.search(r"point 'P\d+' \(y\) is nearly undetermined", err), err


@pytest.mark.parametrize("eps, words", [(0.0, "exactly zero pivot"), (1e-13, "scaled pivot")])
def test_the_sparse_factor_names_the_unknown_of_its_failed_pivot(eps, words):
    """Unit normals of 500 unknowns with one pair coupled to (nearly) one: the pivot fails
    on one of the two, in the order of the free unknowns, also with a datum defect held out."""
    p, a, b = 500, 123, 321
    N = sparse.lil_matrix(sparse.identity(p))
    N[a, b] = N[b, a] = 1.0 - eps
    f = factorize(sparse.csc_matrix(N))
    assert not f.ok and words in f.message and f.weak in (a, b), (f.message, f.weak)
    # a defect in front (two unknowns seen only by their sum), one of them held as the datum:
    # the pivot's unknown is still given among all the free ones
    Nd = sparse.block_diag([np.ones((2, 2)), N], format="csc")
    G = np.zeros((p + 2, 1))
    G[:2, 0] = [1.0, -1.0]
    f = factorize(Nd, G, G)
    assert not f.ok and words in f.message and f.weak in (a + 2, b + 2), (f.message, f.weak)


@pytest.mark.parametrize("sig", ["SIGTERM", "SIGHUP", "SIGINT"])
def test_a_stop_signal_while_sim_loads_is_one_line_and_exit_130(sig):
    done = python_lines(
        "import os, signal, time",
        "from sim.threads import interrupt_while_loading",
        "loaded = interrupt_while_loading('sim')",
        "h = signal.getsignal(signal.SIGTERM)",
        "loaded()",
        "assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL is not h",
        "interrupt_while_loading('sim')",
        f"os.kill(os.getpid(), signal.{sig})",
        "time.sleep(30)",
    )
    assert done.returncode == 130 and done.stderr == "sim: interrupted\n", done


def test_ctrl_c_while_the_pool_forks_is_not_lost():
    """An interrupt raised in the parent's at-fork hook (where a real Ctrl-C lands now and
    then) was swallowed; now it reaches the caller as KeyboardInterrupt; the workers block no signal (a SIGTERM
    from the pool's close still ends them)."""
    done = python_lines(
        "import os, signal, sys",
        "from sim.mc.executors import _Pool",
        "os.register_at_fork(after_in_parent=lambda: os.kill(os.getpid(), signal.SIGINT))",
        "try:",
        "    _Pool(1)",
        "except KeyboardInterrupt:",
        "    sys.exit(130)",
    )
    assert done.returncode == 130 and "Exception ignored" not in done.stderr, done
    done = python_lines(
        "import signal",
        "from sim.mc.executors import _Pool",
        "p = _Pool(1)",
        "assert p.start_method != 'fork' or not signal.pthread_sigmask(signal.SIG_BLOCK, [])",
        "f = p.pool.submit(signal.pthread_sigmask, signal.SIG_BLOCK, [])",
        "assert not f.result(timeout=30), f.result()",
        "p.close(kill=True)",
    )
    assert done.returncode == 0, done.stderr[-800:]


def test_ctrl_c_in_the_first_import_of_sim_is_one_line():
    done = python_lines(
        "import os, signal, sys",
        "assert 'logging' not in sys.modules",
        "class Hook:",
        "    def find_spec(self, name, path=None, target=None):",
        "        if name == 'logging':",
        "            os.kill(os.getpid(), signal.SIGINT)",
        "sys.meta_path.insert(0, Hook())",
        "sys.argv = ['sim']",
        "import sim.__main__",
    )
    assert done.returncode == 130 and done.stderr == "sim: interrupted\n", done
