"""Golden model of the Fast Multi-Touch (FMT) controller.

Every block of the RTL has a twin here.  Floating-point functions are the accuracy
reference; fixed-point functions (``*_fixed``) reproduce the RTL bit for bit.
"""
