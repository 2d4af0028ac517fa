"""The mutation report's hand-checked notes (tests/mutation_report.py) go to the mutant they
were checked on: keyed by number alone, a note came to stand under another mutant's diff once
the module changed and mutmut numbered its mutants anew ("equivalent: getattr's default None"
under a diff of ``as_printed(dict(None))``)."""

import mutation_report as mr

NAME = "sim.claims.rules.x__shown__mutmut_9"
LINE = mr.CHECKED[NAME]


def test_a_note_goes_to_its_own_mutant():
    assert mr.note_for(NAME, [LINE]) == (mr.NOTES[NAME], False)


def test_a_note_follows_its_mutated_line_when_the_numbers_shift():
    assert mr.note_for("sim.claims.rules.x__shown__mutmut_12", [LINE]) == (mr.NOTES[NAME], False)


def test_a_note_stays_off_another_diff_and_says_so_under_its_old_number():
    assert mr.note_for(NAME, ["return str(v)"]) == (None, True)
    assert mr.note_for("sim.claims.rules.x__shown__mutmut_3", ["return str(v)"]) == (None, False)


def test_a_note_stays_off_another_function_with_the_same_line():
    assert mr.note_for("sim.claims.rules.x_other__mutmut_9", [LINE]) == (None, False)


def test_every_note_has_the_line_it_was_checked_against():
    assert set(mr.NOTES) == set(mr.CHECKED)
