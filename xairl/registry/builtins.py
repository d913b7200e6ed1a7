"""The built-in plugin: registers xairl's own attributors and example policy through the public hooks."""

from xairl.registry.hookspecs import hookimpl


@hookimpl
def register_attributors(register):
    register(
        "deep_shap",
        "xairl.attributors.deep_shap:DeepShap",
        "DeepSHAP: DeepLIFT rescale multipliers over the background; fast, exact additivity",
    )
    register(
        "kernel_shap",
        "xairl.attributors.kernel_shap:KernelShap",
        "KernelSHAP (shap): model-agnostic, sampled coalitions",
    )
    register(
        "integrated_gradients",
        "xairl.attributors.integrated_gradients:IntegratedGradients",
        "Integrated Gradients (captum) from the background mean",
    )
    register(
        "exact",
        "xairl.attributors.exact:Exact",
        "exact interventional Shapley values by enumerating coalitions (<= 16 features)",
    )


@hookimpl
def register_policies(register):
    register("toy", "xairl.toy:toy_policy", "a tiny seeded 5-feature, 3-action MLP for trying xairl out")


@hookimpl
def register_narrators(register):
    register(
        "template", "xairl.narrators.template:TemplateNarrator", "deterministic: the first phrasing of each sentence"
    )
    register(
        "local_lm",
        "xairl.narrators.local_lm:LocalLMNarrator",
        "a small local language model (SmolLM2-135M by default) words the facts; verified, template fallback",
    )
