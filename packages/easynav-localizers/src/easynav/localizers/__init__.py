"""EasyNav localizers: the simple AMCL particle filter."""
