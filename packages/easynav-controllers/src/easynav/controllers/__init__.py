"""EasyNav controllers: SimpleController."""
