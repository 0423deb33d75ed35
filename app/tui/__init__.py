"""The vtool terminal application (Textual): valve-train, sonic-boom and plate screens.

Build it with :func:`vtool.app.tui.app.create_app`; ``vtool tui`` runs it.
"""
