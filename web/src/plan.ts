// Reading the pass plan: the passes of a mode, the resources its steps name,
// and what the plan does with each resource (which decides its usages).

import type { Mode, ModePlan, Pass, Plan, PlanDevice, ResourceDesc, ResourceId } from './contract.js';
import { engineBound, resourceKey } from './contract.js';

/** The plan of `mode` on `device`: the mode's plan for that kind of device, else its plan for every device. */
export function modePlan(plan: Plan, mode: Mode, device: PlanDevice): ModePlan | undefined {
  const of = plan.modes.filter((m) => m.mode === mode);
  return of.find((m) => m.device === device) ?? of.find((m) => m.device === undefined);
}

/** The compute passes of a mode, in order. */
export function passes(mode: ModePlan): Pass[] {
  return mode.steps.flatMap((s) => (s.step === 'pass' ? [s] : []));
}

/** Every resource a mode's steps name, each once, in order of first mention. */
export function modeResources(mode: ModePlan): ResourceId[] {
  const seen = new Map<string, ResourceId>();
  const add = (id: ResourceId) => {
    if (!seen.has(resourceKey(id))) seen.set(resourceKey(id), id);
  };
  for (const step of mode.steps) {
    if (step.step !== 'pass') {
      add(step.resource);
      continue;
    }
    step.bindings.forEach((b) => add(b.resource));
    for (const d of step.dispatches) {
      if (d.arguments) add(d.arguments);
      if (d.workgroups.kind === 'indirect') add(d.workgroups.buffer);
    }
  }
  return [...seen.values()];
}

/** The descriptors of the runtime-owned resources a mode uses. */
export function planResources(plan: Plan, mode: ModePlan): ResourceDesc[] {
  return modeResources(mode)
    .filter((id) => !engineBound(id))
    .map((id) => {
      const desc = plan.resources.find((r) => resourceKey(r.id) === resourceKey(id));
      if (!desc) throw new Error(`the plan names ${resourceKey(id)} but does not describe it`);
      return desc;
    });
}

/** What the plan does with a resource, over every mode. */
export interface Uses {
  cleared: boolean;
  readBack: boolean;
  indirect: boolean;
  sampled: boolean;
}

export function resourceUses(plan: Plan): Map<string, Uses> {
  const uses = new Map<string, Uses>();
  const of = (id: ResourceId): Uses => {
    const key = resourceKey(id);
    let u = uses.get(key);
    if (!u) uses.set(key, (u = { cleared: false, readBack: false, indirect: false, sampled: false }));
    return u;
  };
  for (const step of plan.modes.flatMap((m) => m.steps)) {
    if (step.step === 'clear') of(step.resource).cleared = true;
    else if (step.step === 'readback') of(step.resource).readBack = true;
    else {
      for (const b of step.bindings) {
        if (b.type.kind === 'record_texture' || b.type.kind === 'uint_texture') of(b.resource).sampled = true;
      }
      for (const d of step.dispatches) {
        if (d.workgroups.kind === 'indirect') of(d.workgroups.buffer).indirect = true;
      }
    }
  }
  return uses;
}

/** The most passes any mode records: the timestamp slots a runtime reserves. */
export function mostPasses(plan: Plan): number {
  return Math.max(0, ...plan.modes.map((m) => passes(m).length));
}
