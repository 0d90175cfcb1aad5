"""`pinmech design FILE`: a page in the browser where a drawn linkage is designed by dragging.

The browser draws (plain SVG and one small script, `static/`); the engine computes: every
change of the drawing is a new linkage spec (`edits.py`), solved over a whole turn as
`pinmech sweep` solves it (`frame.py`), its diagnostics read from the sweep's own
(`diagnostics.py`), sent to the page as one JSON frame (`session.py`) over a websocket
(`server.py`, Starlette on uvicorn, 127.0.0.1 only, a random token in the address).
`save.py` writes the linkage, a scene and the figures; `synthesis.py` runs `synthesise`
from targets clicked on the page.
"""
