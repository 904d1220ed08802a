"""Tools that run the library from outside: the validation suite and the benchmarks. The core never imports this package."""
