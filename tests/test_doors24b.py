"""Doors sweep 24b, a user at real size: the memory estimates of a large network against what
its sparse factor really holds.

The sparse path's chunk estimate (``sim check``'s refusal, :func:`chunk_bytes`) and the
pre-run estimate (:mod:`sim.mc.network_size`, against ``SIM_MAX_MEMORY_GB``) counted the
normals' nonzeros as the rows' slot pairs ``m s^2``: a 10,000-point trilateration grid's
factor 11 times its real size, and a 50,000-point grid refused at every chunk ("a chunk of 4
trials needs about 3.9 GiB ... use a smaller chunk") though it ran in 1.3 GiB. The tests
measure the factor at a size that runs in a second.
"""

from __future__ import annotations

import numpy as np
import pytest

from sim.lsq import sparse as lsq_sparse
from sim.mc import network_size
from sim.mc.config import ConfigError
from sim.studies import load_study
from sim.studies.network import schema
from sim.studies.network.definition import build
from sim.studies.network.model import datum, jacobian_sparse, pattern, use_sparse
from sim.studies.network.sparse_analysis import _pairs, chunk_bytes, factor


def _grid(tmp_path, side=24, extra=""):
    """A side x side trilateration grid (distances to the 8 nearest), inner datum."""
    f = tmp_path / "grid.toml"
    f.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\nseed = 3\n[network]\n'
        f'grids = [ {{ prefix = "P", nx = {side}, ny = {side}, spacing_m = 100.0 }} ]\n'
        'generate = [ { kind = "distance", from = "P*", to = "P*", nearest = 8, '
        f'sigma_mm = 1.0 }} ]\n{extra}[datum]\nkind = "inner"\n'
    )
    _, cfg = load_study(f)
    return cfg


def _arrays(net, chunk, nnz_l):
    """:func:`chunk_bytes`'s model with the factor's nonzeros given."""
    return network_size.sparse_chunk_bytes(chunk, net.m, net.q, nnz_l)


def _held(net, chunk, nnz_l):
    """The run's model of the built network (:func:`network_size.network_estimate`'s): a
    chunk and the network's state (lead32: its points and the normals' assembly)."""
    s = pattern(net).shape[1]
    state = network_size.state_bytes(net.n, net.m, s > 4)
    return max(_arrays(net, chunk, nnz_l) + state, network_size.state_bytes(net.n, net.m))


@pytest.mark.parametrize("extra", ["", "estimate_scale = true\nestimate_constant = true\n"])
def test_normals_nonzeros_counts_the_normals_the_engine_assembles(tmp_path, extra):
    cfg = _grid(tmp_path, 12, extra)
    net = build(cfg)
    free = datum(net, cfg).free_index(net.q)
    cols = pattern(net)
    _, vals = jacobian_sparse(net, net.theta_true()[None])
    N = lsq_sparse.normals(cols, vals[0], 1.0 / net.sigma**2, free, net.q, _pairs(net))
    held = np.setdiff1d(np.arange(net.q), free)
    counted = lsq_sparse.normals_nonzeros(np.where(np.isin(cols, held), -1, cols), net.q)
    assert counted == N.nnz  # the pattern, duplicates summed, cancelled sums kept
    assert counted < net.m * cols.shape[1] ** 2 / 4  # far from the slot pairs m s^2


def test_chunk_estimate_follows_the_measured_factor(tmp_path):
    cfg = _grid(tmp_path)
    net = build(cfg)
    assert use_sparse(net)
    real = factor(net, datum(net, cfg)).nnz  # the factor the run holds
    for chunk in (1, 20):
        est, measured = chunk_bytes(net, chunk), _arrays(net, chunk, real)
        # an estimate, never below what the factor holds, and not a multiple of it
        assert measured <= est <= 2.0 * measured, (chunk, est / measured)


def test_pre_run_estimate_follows_the_built_network(tmp_path):
    """The declaration's estimate (no network built) within 3x of the built network's."""
    cfg = _grid(tmp_path)
    net = build(cfg)
    real = factor(net, datum(net, cfg)).nnz
    _, _, U, b = network_size.network_estimate(cfg)
    assert U >= 400  # the sparse branch of the estimate
    measured = _held(net, cfg["chunk"], real)
    assert measured <= b <= 3.0 * measured, b / measured


def test_a_network_too_large_at_one_trial_is_not_told_to_use_a_smaller_chunk(tmp_path, monkeypatch):
    cfg = _grid(tmp_path, 12)
    cfg["chunk"] = 1
    cfg["trials"] = 20
    net = build(cfg)
    monkeypatch.setattr(schema, "MAX_CHUNK_BYTES", chunk_bytes(net, 1) / 2)
    with pytest.raises(ConfigError) as e:
        schema.check(cfg)
    assert e.value.key == "network"
    assert "smaller chunk" not in str(e.value) and "a chunk of one trial too" in str(e.value)


def test_a_dense_networks_figure_draws_ellipses_apart(tmp_path, monkeypatch):
    """A 60 x 60 grid (3,600 points): ellipses at no more than SIDE x SIDE points, each apart
    from the next, and markers smaller than a sparse network's (a 142 x 142 grid was a blue
    square with its 20,164 ellipses 1 pt across underneath)."""
    from sim.studies.network import figures
    from sim.studies.network.sparse_analysis import analyse_sparse

    cfg = _grid(tmp_path, 60)
    net = build(cfg)
    an = analyse_sparse(net, datum(net, cfg), 0.001, 0.8)
    seen = {}
    monkeypatch.setattr(figures, "save", lambda fig, path: seen.setdefault("fig", fig) and path)
    figures.network_figure(net, an, np.arange(net.n), tmp_path / "n.png")
    ax = seen["fig"].axes[0]
    lines = [c for c in ax.collections if hasattr(c, "get_segments")]
    ell = [c for c in lines if len(c.get_segments()) and len(c.get_segments()[0]) == 61]
    assert len(ell) == 1 and len(ell[0].get_segments()) <= 50**2  # figures.SIDE
    dots = [c for c in ax.collections if c.get_label() == "estimated point"]
    assert dots and float(dots[0].get_sizes()[0]) < 2
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any(f"of the {net.n:,} points" in t for t in labels), labels
