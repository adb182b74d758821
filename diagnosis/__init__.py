"""Closing the loop: from the residual to the missing effect, calibrated, before and after."""
