"""Reports: the reference study's tables and figures regenerated from experiment stores."""
