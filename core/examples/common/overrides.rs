//! A preset with some of its values replaced from `field=json` arguments (the preset tools).

use sylva_core::species::Species;

/// The preset `name` with each `field=json` pair of `pairs` set (a dotted field, such as
/// `looks.leaf_length`, sets a field of an object); stops the tool with a message for an unknown
/// preset, a malformed pair or a species that does not validate.
pub fn species_with_overrides(name: &str, pairs: &[String]) -> Species {
    let preset = Species::by_name(name).unwrap_or_else(|e| panic!("{e}"));
    let mut fields = serde_json::to_value(&preset).expect("a species serializes");
    for pair in pairs {
        let (key, value) = pair
            .split_once('=')
            .unwrap_or_else(|| panic!("{pair}: expected field=value"));
        let slot = key
            .split('.')
            .fold(&mut fields, |object, field| &mut object[field]);
        *slot = serde_json::from_str(value).unwrap_or_else(|e| panic!("{pair}: {e}"));
    }
    let species: Species = serde_json::from_value(fields).unwrap_or_else(|e| panic!("{e}"));
    if let Err(why) = species.validate() {
        eprintln!("not a valid species: {why}");
        std::process::exit(1);
    }
    species
}
