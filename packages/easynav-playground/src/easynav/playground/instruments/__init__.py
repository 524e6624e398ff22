"""Measuring instruments: plugins that make EasyNav's reactions observable from outside."""
