"""The parts of bench/flow_benchmark.py, the side-by-side benchmark of YADE's FlowEngine and PFV's: its scene
(packings, permeameter, oedometer, engines), its trials (run in yade children), their summary and the Markdown
report of doc/benchmarks.md. The protocol is in bench/flow_benchmark.py's docstring."""
