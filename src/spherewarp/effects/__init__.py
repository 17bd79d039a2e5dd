"""Effects: what finds a map's parameters and renders it.

A map (:mod:`spherewarp.maps`) is mathematics: a function of the sphere with
its JSON form. An effect is the workflow round one: Droste's picture frames
and automatic scale (:mod:`~spherewarp.effects.droste`), split-screen's seams
and cross-fades (:mod:`~spherewarp.effects.splitscreen`), the toroidal image
and its mesh (:mod:`~spherewarp.effects.torus`). The modules are imported on
use, so that ``import spherewarp`` stays fast.

Examples
--------
>>> from spherewarp.effects import droste, splitscreen, torus
>>> callable(splitscreen.splitscreen), callable(torus.render_torus)
(True, True)
"""
