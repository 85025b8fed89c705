"""The controller suite: generated tracking problems run by every articula method and by the
peers people already use (mink), side by side."""
