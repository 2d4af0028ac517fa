"""GNU Gama's ``gama-local`` vocabulary (2.x: its schema ``gama-local.xsd`` and its parser):
the elements, their attributes and the values an attribute may take, the elements refused
(3-D and 1-D data), and the checked reading of a file and of its numbers -- every message
one :class:`~sim.mc.config.ConfigError` line naming the file, the element and the attribute.
Only a regular file of at most :data:`MAX_BYTES` is read (a FIFO or a device is refused
before it is opened). The parser: :mod:`sim.studies.network.gama_read`; what gama-local's own
parser sees first (entities, prefixed names): :mod:`sim.studies.network.gama_prolog`."""

from __future__ import annotations

import decimal
import math
import os
import re
import stat
from pathlib import Path

from sim.mc.config import ConfigError
from sim.mc.numtext import UnheldError, float_text
from sim.mc.paths import link_problem
from sim.studies.network.validate import _point_name

__all__ = [
    "NS",
    "CC",
    "MAX_BYTES",
    "MAX_TURNS",
    "VOCAB",
    "read_bytes",
    "ws",
    "words",
    "said",
    "shifted",
    "drop_empty",
    "parameters_note",
]

NS = "http://www.gnu.org/software/gama/gama-local"
CC = math.pi / 200 / 10000  # one centesimal second in rad
#: largest gama-local file read (bytes)
MAX_BYTES = 16 * 1024**2
#: a number as gama-local's C parser reads it: ASCII digits only (Python's float and ``\d``
#: would also take Arabic-Indic or full-width digits); one way to match each digit (``\d+\.?\d*``
#: split a run of digits every way: a 10 MB attribute of digits ending in garbage hung, doors31y)
_NUM = re.compile(r"^[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?$", re.ASCII)
_DMS = re.compile(r"^[+-]?\d+-\d+-\d+(\.\d*)?([eE][+-]?\d+)?$", re.ASCII)
#: gama-local's integers: a ``<cov-mat>``'s dim and band are digits only (its ``toIndex``), the
#: ``cov-band`` digits with a sign (``IsInteger``): "2.0", "2e0" are refused there
_INDEX = re.compile(r"^\d+$", re.ASCII)
_INTEGER = re.compile(r"^[+-]?\d+$", re.ASCII)
#: the largest degrees or minutes of a d-m-s value: gama-local reads them into a C int (more:
#: "bad angle")
_INT_MAX = 2**31 - 1
#: the most turns an angular value (``val``, ``<obs orientation>``) may hold: ``gama-local``
#: reduces it one turn a step (see :meth:`_File.turns`)
MAX_TURNS = 1000
#: the white space XML (and gama-local) trims around a value and splits a list at: Python's
#: ``strip()`` and ``split()`` also take a no-break space and the other Unicode spaces, so an id
#: ``"A\u00a0"`` was the point ``A`` here and another point in gama-local (doors24c)
XML_WS = " \t\r\n"
_WS_RUN = re.compile(r"[ \t\r\n]+")


def said(v: str, most: int = 19) -> str:
    """``repr(v)`` for a message, cut to its first ``most`` characters with its length when
    longer: a 10 MB attribute was echoed whole into the one-line refusal (19: a longer run of
    digits is shown as a float by every ConfigError, 40 nines as '1e+40')."""
    if len(v) <= most:
        return repr(v)
    return f"{v[:most]!r}... ({len(v):,} characters)"


def ws(v: str) -> str:
    """``v`` without the XML white space around it (a no-break space stays, as in gama-local)."""
    return v.strip(XML_WS)


def words(v: str | None) -> list[str]:
    """The words of a list value (a ``<cov-mat>``'s numbers, ``distance-stdev``), split at XML
    white space only."""
    return [w for w in _WS_RUN.split(ws(v or "")) if w]


_XYZ = ("xy", "XY", "z", "Z", "xyz", "XYZ", "XYz", "xyZ")
#: gama-local's vocabulary: element -> its attributes (``language`` and ``encoding`` are options
#: of its command line, which its parser refuses on ``<parameters>``: unknown here too)
VOCAB = {
    "gama-local": {"version"},
    "network": {"axes-xy", "angles", "epoch"},
    "description": set(),
    "parameters": {
        "sigma-apr",
        "conf-pr",
        "tol-abs",
        "sigma-act",
        "update-constrained-coordinates",
        "algorithm",
        "angles",
        "latitude",
        "ellipsoid",
        "cov-band",
    },
    "points-observations": {
        "distance-stdev",
        "direction-stdev",
        "angle-stdev",
        "zenith-angle-stdev",
        "azimuth-stdev",
    },
    "point": {"id", "x", "y", "z", "fix", "adj"},
    "obs": {"from", "orientation", "from_dh"},
    "direction": {"to", "val", "stdev", "from_dh", "to_dh", "extern"},
    "distance": {"from", "to", "val", "stdev", "from_dh", "to_dh", "extern"},
    "angle": {
        "from",
        "bs",
        "fs",
        "to",
        "rs",
        "val",
        "stdev",
        "from_dh",
        "bs_dh",
        "fs_dh",
        "extern",
    },
    "cov-mat": {"dim", "band"},
    "coordinates": {"extern"},
    "vectors": set(),
    "vec": {"from", "to", "dx", "dy", "dz", "from_dh", "to_dh", "extern"},
}
#: where each element may stand (gama-local.xsd): element -> the elements that may hold it; one
#: elsewhere (a <point> inside <parameters>) would be skipped by the reader: it is refused
PARENTS = {
    "network": {"gama-local"},
    "description": {"network"},
    "parameters": {"network"},
    "points-observations": {"network"},
    "point": {"points-observations", "coordinates"},
    "obs": {"points-observations"},
    "direction": {"obs"},
    "distance": {"obs"},
    "angle": {"obs"},
    "cov-mat": {"obs", "coordinates", "vectors", "height-differences"},  # the last: refused
    "coordinates": {"points-observations"},
    "vectors": {"points-observations"},
    "vec": {"vectors"},
}
_CHOICES = {
    ("network", "axes-xy"): ("ne", "sw", "es", "wn", "en", "nw", "se", "ws"),
    ("network", "angles"): ("left-handed", "right-handed"),
    ("parameters", "sigma-act"): ("aposteriori", "apriori"),
    ("parameters", "update-constrained-coordinates"): ("yes", "no"),
    ("parameters", "angles"): ("400", "360"),
    ("point", "fix"): _XYZ,
    ("point", "adj"): _XYZ,
}
#: the attributes ``gama-local`` reads as absent when empty (``x=""``, ``stdev=""``: its parser
#: tests ``if (sv != "")``): the default holds there (a point without coordinates, the default
#: stdev); :func:`drop_empty` removes them, so that they are read here as there. An empty value
#: of any other attribute is refused there and here (``id=""``, ``val=""``, ``sigma-apr=""``)
_OBS_OPTIONAL = ("stdev", "from_dh", "to_dh", "bs_dh", "fs_dh", "extern")
EMPTY_IS_ABSENT = {
    "point": ("x", "y", "z", "fix", "adj"),
    "obs": ("from", "orientation", "from_dh"),
    "distance": _OBS_OPTIONAL,
    "direction": _OBS_OPTIONAL,
    "angle": _OBS_OPTIONAL,
    "vec": ("from_dh", "to_dh", "extern"),
    "coordinates": ("extern",),
}
_REFUSED = {
    "s-distance": "slope distances are 3-D",
    "z-angle": "zenith angles are 3-D",
    "azimuth": "azimuths are not supported",
    "height-differences": "height differences are 1-D (heights)",
    "dh": "height differences are 1-D (heights)",
}


def _tag(e) -> str:
    return e.tag.split("}", 1)[-1] if isinstance(e.tag, str) else ""


def shifted(text: str, places: int) -> decimal.Decimal:
    """The decimal number ``text`` spells times ``10 ** places``, exactly (its digits kept,
    its exponent moved: no rounding to a context's precision)."""
    sign, digits, exp = decimal.Decimal(text).as_tuple()
    return decimal.Decimal((sign, digits, exp + places))


def drop_empty(root) -> None:
    """Remove the empty attributes ``gama-local`` reads as absent (:data:`EMPTY_IS_ABSENT`)
    from every element under ``root`` (``x="" y=""``: a point without coordinates there)."""
    for e in root.iter():
        for a in EMPTY_IS_ABSENT.get(_tag(e), ()):
            if e.get(a) == "":
                del e.attrib[a]


class _File:
    """Error helper: every message names the file, the element and the attribute."""

    def __init__(self, key: str, path: Path):
        self.key, self.path = key, path
        #: d-m-s values with minutes or seconds of 60 or more, read as gama-local reads them:
        #: ``(element, attribute, value)``, for the note
        self.sexagesimal: list[tuple[str, str, str]] = []
        #: said after a refused point name where the file's bytes are UTF-8 under another
        #: declaration (its names read as other characters: ``gama_encoding.utf8_note``)
        self.names_hint = ""

    def err(self, e, what: str, attr: str | None = None) -> ConfigError:
        where = f"<{_tag(e)}>" if attr is None else f"<{_tag(e)}> attribute {attr!r}"
        pid = e.get("id") or e.get("to")
        at = f" ({'id' if e.get('id') else 'to'}={said(pid)})" if pid and attr != "id" else ""
        return ConfigError(self.key, f"{self.path}: {where}{at}: {what}")

    def num(self, e, attr: str, default: float | None = None, lo: float | None = None) -> float:
        v = e.get(attr)
        if v is None:
            if default is None:
                raise self.err(e, "missing", attr)
            return default
        if not _NUM.match(ws(v)):
            raise self.err(e, f"{said(v)} is not a number", attr)
        try:  # "-0" is 0.0 (atan2 tells -0.0 apart: other results); 1e-400 not 0, silently
            x = float_text(ws(v))
        except UnheldError as why:
            raise self.err(e, str(why), attr) from None
        if lo is not None and x <= lo:
            raise self.err(e, f"{said(v)} must be > {lo:g}", attr)
        return x

    def integer(self, e, attr: str, signed: bool = False) -> int:
        """An integer attribute as gama-local reads it: ASCII digits (with a sign where
        ``signed``) and white space around them; "2.0" or "2e0" is refused, as there."""
        v = e.get(attr)
        if v is None:
            raise self.err(e, "missing", attr)
        if not (_INTEGER if signed else _INDEX).match(ws(v)):
            what = "an integer" if signed else "a whole number of digits"
            raise self.err(e, f"{said(v)} is not {what} (gama-local refuses it)", attr)
        return int(ws(v)) if len(ws(v)) < 100 else _INT_MAX  # int() of 5000 digits: ValueError

    def mm(self, e, attr: str) -> float:
        """A coordinate of the file (metres) in millimetres: its decimal digits moved by three
        places (``-256.034379`` is -256034.379 mm, where ``-256.034379 * 1000`` is
        -256034.37900000002), so the export's coordinates read back to the last digit."""
        self.num(e, attr)
        return float(shifted(ws(e.get(attr)), 3)) + 0.0  # -0 is 0

    def name(self, e, attr: str, default: str | None = None) -> str:
        v = e.get(attr, default)
        if v is None or not ws(v):
            raise self.err(e, "missing point name", attr)
        # gama-local's PointID trims the id and makes each run of white space one space:
        # "A  B" and "A B" are one point there (two points here, read silently, doors32g)
        v = " ".join(words(v))
        try:
            return _point_name(attr, v)
        except ConfigError as err:
            raise self.err(e, str(err).split(": ", 1)[1] + self.names_hint, attr) from None

    def angle(self, e, attr: str = "val") -> bool:
        """Check an angular value; True when it is d-m-s (degrees), False for gon. A d-m-s
        value is read as ``gama-local`` reads it (``deg2gon``): degrees and minutes any C
        ``int``, seconds any number, d + m/60 + s/3600 (``10-75-0`` is 11 degrees 15 minutes;
        such values are listed in :attr:`sexagesimal` for the note)."""
        v = ws(e.get(attr) or "")
        if not v:
            raise self.err(e, "missing", attr)
        if _DMS.match(v):
            d, m, s = v.lstrip("+-").split("-", 2)  # seconds of 3e-5: one more "-"
            try:  # seconds of 1e-400 are no 0 (or 1e400 no inf), as any number of the file
                sec = float_text(s)
            except UnheldError as why:
                raise self.err(e, f"{said(v)}: the seconds {why}", attr) from None
            for part, unit in ((d, "degrees"), (m, "minutes")):  # gama-local's int overflows
                # (int() of 5000 digits: ValueError; leading zeros are no digits of it)
                if len(part.lstrip("0")) > 10 or int(part.lstrip("0") or "0") > _INT_MAX:
                    raise self.err(
                        e, f"{said(v)}: over {_INT_MAX} {unit}, refused by gama-local", attr
                    )
            minutes = int(m.lstrip("0") or "0")
            if minutes >= 60 or sec > 60:  # 60.00 seconds: a value rounded up, not listed
                self.sexagesimal.append((_tag(e), attr, v))
            degrees = int(d.lstrip("0") or "0") + minutes / 60 + sec / 3600
            if attr == "val":  # an observed angle, which gama-local reduces
                self.turns(e, attr, degrees / 360)
            return True
        gon = self.num(e, attr)
        if attr == "val":
            self.turns(e, attr, gon / 400)
        return False

    def turns(self, e, attr: str, turns: float) -> None:
        """Refuse an angle of more than :data:`MAX_TURNS` turns: ``gama-local`` reduces an
        angle by one turn a step (``norm_rad_val``, its absolute terms), which loses the
        angle's last digits past thousands of turns (1e-8 rad at 1e4, 1e-3 rad at 6e6: the
        degrees of a C ``int``) and never ends past about 1e16 radians (``val="1e17"`` held
        it, and this reader, for good; 6e6 turns took this reader 4 s a value)."""
        if not abs(turns) <= MAX_TURNS:
            raise self.err(
                e,
                f"{said(ws(e.get(attr)))}: {abs(turns):.3g} turns, over {MAX_TURNS} (gama-local "
                "reduces an angle one turn a step: past thousands of turns it loses the angle's "
                "last digits, and it never ends on 1e16 radians or more): give it within a turn",
                attr,
            )

    def vocab(self, root) -> None:
        for parent in root.iter():  # every element's place (iterative: any depth)
            for e in parent:
                if isinstance(e.tag, str) and _tag(parent) not in PARENTS.get(_tag(e), {""}):
                    if _tag(e) in VOCAB and _tag(e) not in _REFUSED:
                        raise self.err(e, f"not allowed inside <{_tag(parent)}>")
                if _tag(e) == "cov-mat" and e is not parent[-1]:  # gama-local reads none after it
                    raise self.err(e, f"one <cov-mat>, the last element of its <{_tag(parent)}>")
        for e in root.iter():
            t = _tag(e)
            ns = e.tag[1:].split("}", 1)[0] if isinstance(e.tag, str) and e.tag[:1] == "{" else NS
            if ns != NS:
                raise self.err(e, f"in the namespace {ns!r}, not gama-local's ({NS})")
            if t in _REFUSED:
                raise self.err(e, f"not supported: {_REFUSED[t]} (2-D networks only)")
            if t not in VOCAB:
                raise self.err(e, "unknown element (not in gama-local's vocabulary)")
            # XML white space only: gama-local refuses a no-break space between elements
            if t not in ("description", "cov-mat") and ws(e.text or ""):
                raise self.err(e, f"unexpected text {ws(e.text)[:20]!r}")
            if ws(e.tail or "") and e is not root:
                raise self.err(e, f"unexpected text {ws(e.tail)[:20]!r} after it")
            for a, v in e.attrib.items():
                if a.startswith("{" + NS + "}"):  # g:fix in gama-local's namespace: not fix
                    raise self.err(e, "an attribute with a namespace prefix: write it plainly", a)
                if a.startswith("{") or a == "xmlns":  # another namespace's (xsi:...): not ours
                    continue
                if a not in VOCAB[t]:
                    raise self.err(e, "unknown attribute", a)
                ch = _CHOICES.get((t, a))
                if ch and v not in ch:  # gama-local compares the value as written: " ne" no
                    raise self.err(e, f"{said(v)} is not one of {', '.join(ch)}", a)


def parameters_note(f: _File, pars: list) -> str:
    """Check the ``<parameters>`` element (at most one) and say which ``sigma-act`` the file
    asks for (the study always uses the a-priori stdevs)."""
    if len(pars) > 1:
        raise f.err(pars[1], "given twice")
    p = pars[0] if pars else None
    if p is not None:
        for a, lo in (("sigma-apr", 0.0), ("tol-abs", 0.0)):
            if p.get(a) is not None:
                f.num(p, a, lo=lo)
        if p.get("conf-pr") is not None:
            c = f.num(p, "conf-pr", lo=0.0)
            if c >= 1:
                raise f.err(p, f"{c:g} must be below 1", "conf-pr")
        if p.get("cov-band") is not None:  # any integer: gama-local reads one below -1 as -1
            f.integer(p, "cov-band", signed=True)  # (the whole matrix), and it is not used here
        if p.get("latitude") is not None:
            f.angle(p, "latitude")
    act = "aposteriori" if p is None else ws(p.get("sigma-act", "aposteriori"))
    if act == "apriori":
        return "sigma-act = apriori, as this study: the stdevs are the observations' sigmas"
    return (
        "the file asks for sigma-act = aposteriori (gama-local's default); this study uses "
        "the a-priori stdevs (a pre-analysis has no residuals)"
    )


#: a URL's scheme, as a path keeps it: ``file:///x`` is the path ``file:/x`` (a drive letter is one
#: letter: ``C:/x`` is no URL)
_URL = re.compile(r"^([A-Za-z][A-Za-z0-9+.-]+):/")


def _meant(text: str) -> str:
    """What a path that names nothing likely meant, `` (...)``, or "": a Windows path pasted into
    the study file (``C:\\x.xml``), a ``~`` or ``$HOME`` a shell would have expanded (a study
    file expands neither: "No such file" of a file the user can list), a URL (``file:///x``, whose
    path is given then, or ``https://...``: only a local file is read), white space around the
    name, a name that differs in case from one in its directory."""
    slash = text.replace("\\", "/")
    if slash != text and Path(slash).is_file():
        return f" (did you mean {slash}?)"
    full, what = os.path.expandvars(os.path.expanduser(text)), ""
    if text.startswith("~"):
        what = "'~' is not expanded in a study file"
    elif full != text:
        what = "environment variables are not expanded in a study file"
    if what:
        there = f": {full} exists" if os.path.isfile(full) else ""
        return f" ({what}: give the full path{there})"
    if m := _URL.match(text):
        if m.group(1).lower() != "file":
            return " (a URL: only a local file is read; download it and give its path)"
        local = "/" + text[len("file:") :].lstrip("/")
        there = f": {local} exists" if os.path.isfile(local) else ""
        return f" (a file: URL: give the path itself{there})"
    if ws(text) != text and os.path.isfile(ws(text)):
        return f" (white space around the name: {ws(text)} exists)"
    q = Path(text)
    try:  # (a file system that tells case apart: MyNet.xml for mynet.xml)
        near = next((n for n in os.listdir(q.parent) if n.casefold() == q.name.casefold()), None)
    except (OSError, ValueError):
        near = None
    return f" ({q.parent / near} exists: the name differs in case)" if near else ""


def read_bytes(path: str | Path, key: str = "network.gama_xml") -> bytes:
    """The bytes of ``path``: a regular file of at most :data:`MAX_BYTES` (else one line)."""
    path = Path(path)
    if not str(path).isprintable():  # NUL, or a line break that would split the one line
        what = "a NUL character" if "\0" in str(path) else "a control character"
        raise ConfigError(key, f"{str(path)!r} holds {what}: not a path")
    try:
        st = os.stat(path)
    except OSError as e:
        if why := link_problem(path):  # a loop of links, a name of another Unicode form
            raise ConfigError(key, f"cannot read {path}: it {why}") from None
        raise ConfigError(key, f"cannot read {path}: {e.strerror}{_meant(str(path))}") from None
    if not stat.S_ISREG(st.st_mode):
        raise ConfigError(key, f"{path} is not a regular file")
    if st.st_size > MAX_BYTES:
        raise ConfigError(
            key, f"{path} has {st.st_size} bytes; the limit is {MAX_BYTES} ({MAX_BYTES >> 20} MiB)"
        )
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as fh:
            data = fh.read(MAX_BYTES + 1)
    except OSError as e:
        raise ConfigError(key, f"cannot read {path}: {e.strerror}") from None
    if len(data) > MAX_BYTES:
        raise ConfigError(key, f"{path} is over the limit of {MAX_BYTES} bytes")
    return data
