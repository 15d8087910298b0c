"""Analysis of results: the paper's variables and fits (:mod:`.fits`), DMA fitting of a material
(:mod:`.dma`), the bulk's and the process zone's shares of a pull-off (:mod:`.shares`) and
the figures of a sweep (:mod:`.plots`). Tables in, tables and dicts out.
"""
