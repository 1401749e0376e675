    // Resampling the effects that read {{KEYS}}: only from the corners on the pixel's
    // side of each, with their bilinear weights renormalised.
    let side{{SET}} = {{SIDES}};
    let wt{{SET}} = select(vec4<f32>(0.0), b.weights, side{{SET}});
    let sum{{SET}} = wt{{SET}}.x + wt{{SET}}.y + wt{{SET}}.z + wt{{SET}}.w;
    let torn{{SET}} = !(sum{{SET}} > 0.0); // no corner with a weight on the pixel's side
    b.weights{{SET}} = select(wt{{SET}} / max(sum{{SET}}, 1e-30), b.weights, all(side{{SET}}));
