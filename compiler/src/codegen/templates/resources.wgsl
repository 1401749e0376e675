struct MrslControl {
{{#CONTROL_FIELDS}}
}
@group({{GROUP}}) @binding({{BINDING}}) var<uniform> mrsl_ctl: MrslControl;
{{#USER_RESOURCES}}

// G-buffer channels.
{{#CHANNELS}}

{{#STAGE}}

