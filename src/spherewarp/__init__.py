"""spherewarp."""
