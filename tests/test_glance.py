"""The first screen of REPORT.md (sim.report.glance, issue 25): one row per paper, a second
run of the same study (agnard_block_104) shown as such and not as a second headline, and
numbers at the precision their interval supports."""

from types import SimpleNamespace

from sim.report.glance import _sig3, opening


def _claim(cid, value, lo=None, hi=None, verdict="holds", interval="trials", **kw):
    return {
        "claim": cid,
        "value": value,
        "ci_low": lo,
        "ci_high": hi,
        "verdict": verdict,
        "interval": interval,
        "headline": True,
        "kind": "prediction",
        **kw,
    }


def _entry(dir_name, study_name, seed, claims):
    study = SimpleNamespace(name=study_name, seed_file=seed, title=study_name, order=1)
    return (1, dir_name, study, claims, [])


def test_a_second_run_of_a_study_is_not_a_second_headline(tmp_path):
    main = [_claim("agnard.a", 22.83, 20.7, 25.4), _claim("agnard.b", 1.0, 0.5, 1.5, "fails")]
    big = [_claim("agnard.a", 40.0, 37.0, 48.7, "fails")]
    entries = [
        _entry("agnard_block", "agnard_block", "003_x.txt", main),
        _entry("agnard_block_104", "agnard_block", "003_x.txt", big),
    ]
    text = opening(entries, tmp_path)
    rows = [ln for ln in text.splitlines() if ln.startswith("| **")]
    assert len(rows) == 1 and "[agnard_block](agnard_block/README.md))" in rows[0]
    assert "agnard_block_104" not in rows[0] and rows[0].count("`agnard.a`") == 1
    assert "1 holds, 1 fails" in rows[0]  # the paper's own counts, without the variant's
    note = next(ln for ln in text.splitlines() if "agnard_block_104" in ln)
    assert "the study `agnard_block` again" in note and "1 fails" in note


def test_numbers_at_the_precision_their_interval_supports():
    assert _sig3(_claim("a", 22.8312, 20.71, 25.42)) == "22.8 [20.7, 25.4]"
    assert _sig3(_claim("a", 0.123456, 0.12301, 0.12399)) == "0.123 [0.123, 0.124]"
    assert _sig3(_claim("a", 1234.5, 1000.0, 1500.0)) == "1230 [1000, 1500]"
    # a range over a region whose interval is that range: printed once
    assert _sig3(_claim("a", 4.523, 4.523, 7.241, value_high=7.241)) == "4.5–7.2"
    # a count with a zero-width interval: the count
    assert _sig3(_claim("a", 2.0, 2.0, 2.0)) == "2"
    assert _sig3(_claim("a", -59.2, interval="exact")) == "-59.2"
