"""A GNU Gama ``gama-local`` file of the smallest network the tests read: two fixed points A
and B 1 m apart and a free point (``c``) observed by three distances of 10 mm stdev;
``decl`` goes into the XML declaration (an ``encoding=``), ``extra`` before the points."""

_NET = """<?xml version="1.0" {decl}?>
<gama-local xmlns="http://www.gnu.org/software/gama/gama-local">
  <network axes-xy="ne" angles="left-handed">
    <parameters sigma-apr="1" sigma-act="apriori" />
    <points-observations>
{extra}      <point id="A" x="0.0" y="0.0" fix="xy" />
      <point id="B" x="1.0" y="0.0" fix="xy" />
      <point id="{c}" x="0.4" y="0.7" adj="xy" />
      <obs from="A">
        <distance to="B" val="1.0" stdev="0.01" />
        <distance to="{c}" val="0.806225774829855" stdev="0.01" />
      </obs>
      <obs from="B">
        <distance to="{c}" val="0.921954445729289" stdev="0.01" />
      </obs>
    </points-observations>
  </network>
</gama-local>
"""


def triangle(decl: str = "", c: str = "C", extra: str = "") -> str:
    """The file's text (module docstring)."""
    return _NET.format(decl=decl, c=c, extra=extra)
