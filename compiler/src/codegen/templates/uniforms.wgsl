
struct MrslUniforms {
{{#FIELDS}}
}
@group({{GROUP}}) @binding({{BINDING}}) var<uniform> mrsl_u: MrslUniforms;
