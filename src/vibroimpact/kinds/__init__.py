"""The kinds of study, one folder each, registered in one table (:data:`vibroimpact.scene.kinds.KINDS`).

Each folder holds its kind's scene section (``scene.py``, checked values only, no solver), its run and estimate
(``study.py`` and the modules it sends work from) and its report page (``page.py``, with ``page_for(dataset)``):

* ``stepped``: steady states over parameter grids, closed forms and time-domain engines, any layout;
* ``swept``: swept-sine tests of the compliant model against the steady states;
* ``benchmark``: what accuracy costs, every engine and tolerance against a reference;
* ``bifurcation``: continued branches, special points and two-parameter charts;
* ``validation``: published closed forms reproduced;
* ``concepts``: absorber concepts side by side.

No folder imports another: what two kinds share lives in a layer below them (the stepped and swept kinds'
frequency-grid study is :mod:`vibroimpact.grids`).
"""
