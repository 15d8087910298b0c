"""Analysis of results: the paper's variables and fits (:mod:`.fits`), DMA fitting of a material
(:mod:`.dma`) and the figures of a sweep (:mod:`.plots`). Tables in, tables and dicts out.
"""
