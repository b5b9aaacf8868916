"""The bgmodelica component library: electrical, rotational, blocks, bond graphs, examples."""
