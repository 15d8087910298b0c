"""The paper's reproduction: its campaigns' fits, figures and report (:mod:`.reproduce`,
:mod:`.figures`, :mod:`.report`) and its PDMS experiment (:mod:`.pdms`), computed by this code.
"""
