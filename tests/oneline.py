"""The assertion the door tests share: a command refused bad input with exit 2 and one line on
stderr (no traceback) that holds every needle; the line is returned for more checks."""


def one_line(capsys, rc: int, *needles: str) -> str:
    """The stderr captured by ``capsys`` since its last read, checked as above."""
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "\n" not in err and "Traceback" not in err, (rc, err)
    assert all(n in err for n in needles), err
    return err
