// Second level ({{BLOCK}}x{{BLOCK}}) of the dynamic mode: only effects refined at the first level
// look here; a corner the inner coarse pass did not shade (stale tag) means per-pixel.
