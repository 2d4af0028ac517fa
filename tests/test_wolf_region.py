"""wolf_polynomial's region evidence (sim/studies/wolf/region.py): Table 2's 24 one-plate rows
as one Holm family per input vector, and the headline as the Holm family of the eight plate
means (issue 21; docs/referee-reading.md, Wolf)."""

import numpy as np
import pytest

from sim.claims.family import holm, mc_p
from sim.claims.intervals import plate_p
from sim.mc.config import validate
from sim.studies import wolf
from sim.studies.wolf.chunks import draw_main
from sim.studies.wolf.claims import HEADLINE, JOINT, is_mean_row, load_book, stat_key
from sim.studies.wolf.model import read_placed
from sim.studies.wolf.region import evidence


def _res(book, t2, tags, rng):
    """Per-trial statistics of two cells (every plate and set shares one distribution per
    statistic): plates spread over the four printed numbers at the first point, X shifted far
    above them (rare) at the second."""
    res = {}
    for tag, shift in zip(tags, (0.0, 200.0)):
        for key in dict.fromkeys(stat_key(c) for c in t2):
            refs = [float(book.spec(c)["ref"]) for c in t2 if stat_key(c) == key]
            x = rng.normal(np.mean(refs), 2 * np.ptp(refs) + 1.0, 400)
            res[tag + key] = x + shift * key.endswith("x_um")
    return res


def test_table2_rows_carry_their_holm_adjusted_p_and_the_headline_is_the_means_family():
    book = load_book()
    t2 = [c for c in book.specs if c.startswith("wolf.table2.p")]
    assert len(t2) == 24 and sum(map(is_mean_row, t2)) == 8
    tags = ["g1.0.", "g1.1."]
    res = _res(book, t2, tags, np.random.default_rng(5))
    ev = evidence(book, [HEADLINE, JOINT, *t2[:3]], res, tags)
    raw = np.array(
        [
            [
                plate_p(
                    res[t + stat_key(c)],
                    float(book.spec(c)["ref"]),
                    0.5 * 10.0 ** -book.spec(c)["decimals"],
                )
                for c in t2
            ]
            for t in tags
        ]
    )
    raw = mc_p(raw, 400)
    adj = np.stack([holm(r) for r in raw])
    for k, c in enumerate(t2):
        assert ev[c]["p"] == pytest.approx(adj[:, k], abs=1e-15)
    assert ev[JOINT]["value"] == pytest.approx(adj.min(axis=1), abs=1e-15)
    means = np.array([is_mean_row(c) for c in t2])
    head = [holm(r[means]).min() for r in raw]
    assert ev[HEADLINE]["value"] == pytest.approx(head, abs=1e-15)
    # plates centred on the printed numbers: nothing is rare; shifted X plates: every X row
    # is, and the headline's family of eight with them; 24 rows cannot fail on 400 plates
    # (the smallest Monte-Carlo p is 2 / 401, 24 x that is 0.12)
    assert ev[JOINT]["value"][0] >= 0.05 and ev[HEADLINE]["value"][0] >= 0.05
    assert ev[HEADLINE]["value"][1] == pytest.approx(8 * 2 / 401, abs=1e-15)
    assert ev[JOINT]["value"][1] == pytest.approx(24 * 2 / 401, abs=1e-15)
    # the adjustment only raises a row's p (Holm's factor is at least 1)
    assert np.all(adj >= raw - 1e-15)


def _one_rare_plate(book, t2, k, rng):
    """One cell whose mean-X plates put ``k`` of 400 below the printed 3.0 (plate 005, Set 2)
    and none rare against the other three mean-X numbers; every other statistic centred."""
    tag = "g1.0."
    res = _res(book, t2, [tag, "g1.1."], rng)
    x = np.concatenate([np.full(k, 2.0), np.linspace(3.2, 9.5, 400 - k)])
    res[tag + stat_key("wolf.table2.p005.set2.mean_x_um")] = x
    return res, [tag]


@pytest.mark.parametrize("k, fails", [(0, True), (1, False)])
def test_a_family_is_not_failed_by_one_simulated_plate_in_400(k, fails):
    """Third reading: Holm multiplies the smallest p by the family's size, so the plug-in
    2 k / n let one plate in 400 (p 0.005, 8 x 0.005 = 0.04) fail the headline's family of
    eight. The Monte-Carlo test's p 2 (k + 1) / (n + 1) does not (0.08); no plate at all
    (k = 0, 2 / 401, 8 x that is 0.0399) still fails it. The old plug-in failed both."""
    book = load_book()
    t2 = [c for c in book.specs if c.startswith("wolf.table2.p")]
    res, tags = _one_rare_plate(book, t2, k, np.random.default_rng(11))
    ev = evidence(book, [HEADLINE, JOINT], res, tags)
    assert ev[HEADLINE]["value"][0] == pytest.approx(8 * 2 * (k + 1) / 401, abs=1e-12)
    assert (ev[HEADLINE]["value"][0] < 0.05) == fails
    # the plug-in p of the rare row, as the region used it before: 8 x 2k / 400 < 0.05
    x = res[tags[0] + stat_key("wolf.table2.p005.set2.mean_x_um")]
    assert 8 * plate_p(x, 3.0, 0.05) == pytest.approx(8 * 2 * k / 400) and 8 * 2 * k / 400 < 0.05
    assert mc_p(np.array([0.0, 1.0, 0.05]), 400) == pytest.approx([2 / 401, 1.0, 22 / 401])


def test_the_headline_is_decided_as_one_holm_test_of_the_eight_means():
    spec = load_book().spec(HEADLINE)
    assert spec["form"] == "lower" and spec["ref"] == 0.05 and spec["kind"] == "prediction"
    assert "ranged from 3 to 9" in spec["paper"] and "Holm" in spec["paper"]


def _cfg(**over):
    raw = {"trials": 20, "trade.trials": 10, "unprinted.trials": 10, **over}
    return validate(raw, wolf.SCHEMA, wolf.check)


NC_KEYS = ("field.stress_um", "field.encoder_periodic_um", "field.restitution_um")


@pytest.mark.parametrize("g", [0.0, 2.0])
def test_the_noncubic_factor_cell_equals_scaled_noncubic_amplitudes(g):
    """A region cell's noncubic_factor reads the plates of an instrument configured with the
    stresses, the encoder's periodic error and the restitution field times g (same random
    numbers: the field draws do not depend on the amplitudes)."""
    cfg = _cfg(**{"field.drift_fraction": 0.3})
    cfg2 = dict(cfg, **{k: g * cfg[k] for k in NC_KEYS})
    a = draw_main(cfg, np.random.default_rng(21), 5, 3)
    b = draw_main(cfg2, np.random.default_rng(21), 5, 3)
    kw = dict(count_um=1e-6, n=1, sigma_um=0.0, backlash_um=0.0, approach="one_side")
    kw.update(drift_fraction=0.3, restitution_um=cfg["field.restitution_um"])
    for pa, pb in zip(a["cal"] + a["rep"], b["cal"] + b["rep"]):
        ra = read_placed(pa, noncubic_factor=g, **kw)
        rb = read_placed(pb, **dict(kw, restitution_um=cfg2["field.restitution_um"]))
        assert np.allclose(ra, rb, rtol=0, atol=1e-3)  # counts of 1e-6 um: 1e-9 um
        # the cubic-fittable part is untouched; only the non-cubic part scales
        assert np.allclose(pb.static - pb.static_nc, pa.static - pa.static_nc, atol=1e-9)
        assert np.allclose(pb.drift_nc, g * pa.drift_nc, atol=1e-9)
    # the non-cubic part is a real share of the field, not zero
    assert np.sqrt(np.mean(a["cal"][0].static_nc ** 2)) > 1.0


def test_cells_at_factor_1_read_the_configured_instrument_bit_for_bit():
    cfg = _cfg()
    main = wolf.main_chunk(cfg, full=False)(np.random.default_rng(5), 6)
    cells = wolf.main_chunk(
        cfg,
        (("d.", {"noncubic_factor": 1.0}), ("z.", {"noncubic_factor": 0.0})),
        full=False,
    )(np.random.default_rng(5), 6)
    for k, v in main.items():
        assert np.array_equal(cells["d." + k], v)
    # without the sources a cubic cannot fit, less is left after the cubic
    assert np.mean(cells["z.after.rms_x_um"]) < np.mean(cells["d.after.rms_x_um"])
