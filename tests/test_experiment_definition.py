"""The typed experiment definition: identities of the experiment files, read_definition, gap axes on walls, the shared rules."""

from __future__ import annotations

import copy
import hashlib
import math
import tomllib
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from stochpound.experiment import Experiment, is_rare_event_file, load_rare_event
from stochpound.store import Definition, FIXED_BASE, canonical_json, definition_sha256, is_fixed_base, is_gap_axis, read_definition
from stochpound.experiment._spec import ExperimentError, load_definition, parse_experiment
from stochpound.report.sections._facets import value_text

ROOT = Path(__file__).resolve().parents[1]
EXPERIMENTS = sorted(p for p in (ROOT / "experiments").glob("**/*.toml") if "scenes" not in p.parts and not is_rare_event_file(p))  # rare-event files: their own definition

#: sha256 of an experiment file's bytes -> sha256 of its canonical definition's JSON, as the code gave before the
#: typed definition: the canonical serialisation, and (without a hazard) the identity. A change of the code that
#: changes one of these refuses every store made from that file. (A new version of a file adds its own pair.)
IDENTITIES = {
    "dff3909976ebae73dbef4b1c7e398b3c66732d61c178e1debb73a80981f01404": "a63f03d1e1476471d116da9995f03d845c9e79e14062bb72ce23591ed55bdbe9",
    "638a33ff8b952e185ac07f1fa238740ac38b104a19a0645200932dff86f82be1": "55b4b4b082fba4063464e07d892cf47f9fe52647e8aaf4da1dc51387b674d13f",
    "7ad709e4bbe91a9f92e0c12f96f960fce5174cd54a3a1cf0906d78795a2e9945": "f336d6034b32d583b0db8f048c848c45712cd573d4674dd9f0ccdea44ade869b",
    # experiments/laws/moat_wall.toml (the clearance a gap axis over its walls)
    "7aa99d11cd33c58e32019efbeea980bd3013b663da9288bf85a5e352838fd602": "a288cd8a711ce8d1a0604666aabd69bb434b978fe8fbbecd45a12309dd49defa",
    "eb5a30003676e0a4788bdc77278c680db1928cefaa2e3184526ffb4ff2cd149e": "128add143f75d2a6807a3bdadd1a10eccb86101908995348243d55d4932ab1bb",
    "4904d40c5d2d0af316c9c36b4504f7cfee312861107e92629aed74be5de1066e": "77712e2d264128c8a3ecf4a696d879d37508b4eb254212b076dc9de9f45a36d9",
    "6daeb16f63151e60b79f56d62baf423fe9dc5422dd7830c10c372c48ccf19b93": "6a1f389f07a4ddb74a22fbafd5d9eaf12cfb7b010b75506e2a1437e07f1be195",
    "309e927fcc92995558f608b63070f7e34c624ad733de05db2ef3dd846f46cb13": "d7bad4356301529901f3028369bf45d6dce7588b965a51be782d38c89476ebc1",
    "3a44b36605ea72c0c043259c19a87db1bc5a8500725c7284713e6ff3cfa64452": "913155073613e472c6ef121b0554fa0de7279f648eae93ad48e7312bd1006f1a",
    "93e84ab50ebb80c062ec7a177215421571fafb21faf708e8305b434fedf77a5d": "9ccb32b6d15111c2d0345cd74ac84e5e347b7c48011b942840a44a14ea11a14b",
    "a8d3ad001bdadc3e1c3396bd7a9b21732bc1417c58b9421ed2653e00825f3eb2": "d55d0ae2cae2a3641780d936ed0fa9a61320d035ec519634a8d5a6aacb8d882c",
    "0891f60b747a8f36d97e968b18eca6f258bb1e9f6782da805f763b739f5ba482": "17ac371fe5e1bedc1ee453a2548339086beffba24ce2aaf729d893eb2a9513a5",
    "bd9b53093d44e3e4acc85e308510add994bdf7abef03df62e1f2f88028935856": "4baf14717bf47188d5761c7a878b1636513e2d3c3992b75e15e25c72041021ae",  # experiments/laws/contact_laws.toml
    "b0bc24556ed7b2bb62f13e80740d38c648825a8938a77b173d1000f51d65c729": "6a1f389f07a4ddb74a22fbafd5d9eaf12cfb7b010b75506e2a1437e07f1be195",  # experiments/stochastic/pounding.toml (new header)
    "95b4b472aa9b47e6d561ff939c2384a4662162f7d5fdd8e2d522815203c77ee4": "6a1f389f07a4ddb74a22fbafd5d9eaf12cfb7b010b75506e2a1437e07f1be195",  # experiments/stochastic/pounding.toml (rare cells)
    "d56473cac48340cc68606154cbb115fb794049dc6fb3d77ff1821a7066fcd85a": "8a6ef71bb071e15ec33cd31b3563f219aae44fcad9ced8bf7d78fa71bc127cea",  # experiments/stochastic/scenario_m7_20km.toml
    "086c94dc09671a62f1bfe289e8a0ee7bf0f9ccde3895b7a6d4145f49089990eb": "8a6ef71bb071e15ec33cd31b3563f219aae44fcad9ced8bf7d78fa71bc127cea",  # experiments/stochastic/scenario_m7_20km.toml (re-timed)
    "30f757d6a000b675d5a77664f7ebaac77f5f8fe2bdaaa81c5a883ef996a93fda": "8587d2f9de1b97fd57b3799a668aa67bd90c2019b1ba238e1c664b982fc3c61a",  # experiments/risk/fixed_pair.toml
    "7ee6d0bbad225fc7ce1b98b350144c895ed0d284696c10d4e0c60c6e1901feaf": "45709c88b8c56c21d821c3429b50c35316a024bc8615d148e8dad43a333a280f",  # experiments/risk/fixed_pair.toml (yielding)
    "2ac35eca7fc1effebf5cc3dea300b01aadfa0cc86abb47b348e411247cb9c803": "40f7acef22ebc787ae56e0d0b2a347f5bd6eed6c553e7fbc0902cd26d1a814df",  # experiments/risk/isolated.toml
    "8e4b705fc73ef76afaf17a43eb886385aa0233150b9d597de3b98ff0fa68b8cf": "25d025290edee6b600240034af40615bef4faa550ddd7f1e16dc96666a597c3c",  # experiments/risk/isolated.toml (yielding)
    "d492a28de53b98b32b9f97c777010c9eb02c02dfe0a60221d79efa61f2ba4297": "202e09cad0306790e9903da109697590f847bdbddb7bbe822d5d4b15f5c480f9",  # experiments/risk/fixed_pair.toml (fitted scenario)
    "9b8923b0aa6b1e0b7753b436bf63cf492e61951d6e15670e6b7589efe5611375": "5cfe7294fd8c6bc0974dec1f0c06bbb870620ccc0c9a89a05fbeff4294173b1e",  # experiments/risk/isolated.toml (fitted scenario)
    "55b8a109c6a7fe493d3cf046f0681351cd1070678c42155b611b7cb4991cc95c": "ae6ad2bb5310b9ede71f0267bb215a055113aa32bad2e97696a1f5438d157191",  # experiments/risk/fixed_pair.toml ([design])
    "88dc01b72bd04d6cc226d840a04e24e42421faa9c2bb9dc91a42aab11c0fbfde": "1c1c4b385d2565d2acbc4cbeaa272192f8711728fdffad85425e17a0a5896d41",  # experiments/risk/isolated.toml ([design])
    "76706a47b9ed8d9b9c00281719f78adbbf7cc7ecaa91ed77f8fc343f9cafa29d": "4258c4eeb0c817062b1559066dd537d4c3acf1a9335728732bda3c4116274969",  # experiments/risk/fixed_pair.toml (calibration 3)
    "a9c66c0e67c4e663ca9e1a34a5de92a19ee03c1d8baacb45bb4cf61b70167667": "dab82088050ceca0dcd40466dc94da4533d36efdfff06e7f1145108398b5b3b9",  # experiments/risk/isolated.toml (calibration 3)
    # calibration 4 of the site motions: the definitions name it, so these files' stores of calibration 3 are refused
    "3fd94462383c2c24ee90e370f9f660432ad80b2a147abbcefbc4f63eac0b23b9": "80a800da40b90acc89555feacef32267181a67014591281f7558f1066b61d0d5",  # experiments/risk/fixed_pair.toml (calibration 4)
    "f92271bfab4de9cbe54273e9251be8f1481ef9bedc9860afe355b5bfabb6cfaf": "e221f41b4391da05a806a8dd4e30fb896c6f56bfa28574aabd89e50c53a4ba9b",  # experiments/risk/isolated.toml (calibration 4)
    "2795ab6e166ac0bb0c81264023f74f552426266b1da168551c05111afd5cda99": "1d806055c86a373833f66b75190ab07ef6258b322cbe6f6ff55925b6903153f5",  # stochastic/scenario_m7_20km.toml (calibration 4)
    # calibration 5 (PGA a target of the fit): again the definitions name it
    "7e603f72ad6dc2cc4b5c236cb38f39ae5a01f44568c2bf98c9066e3225e5bf54": "19af4ddbe7eff219f664da68827d55ff6741dd8ac0e43e23f98deb0c4a9303a5",  # experiments/risk/fixed_pair.toml (calibration 5)
    "06dbe7e36e949190951cf046a9f82a161824739cfba7655e097b2799acfd9aac": "f3a55921fe5950299f3d307d982b7299e8774974b41e24b05d5b62dd6ec1d324",  # experiments/risk/isolated.toml (calibration 5)
    "86a14251ac8a879609661c0ee758218c34b18419c2f3f3245a49e31e5e8e98b2": "50bf72d5c1c26fa27c41be45d6b3540cd8555ce3fb349b4a41b013253ed6da88",  # stochastic/scenario_m7_20km.toml (calibration 5)
    "6721b840847f3c887a64063a94280b5d169110c60ef231755da91b89a8300078": "d63aa13f0c17c62515a7f33d09c8af15f2d12f6063f66110f23227a68f70937f",  # experiments/study/gap_study.toml (declares reproduces)
    "2991b119a5949c2c82f9b2fe3c5ea23ba8308484f5adbaf6202633df2547e55f": "0fee6ef18974eda7fe49d0fa885cd06ca430f684281d7e09d9aa13ae02729a4e",  # experiments/study/harmonic.toml (declares reproduces)
    "b7cb8955ddf0e1110227ccc8d346f24b89c5f33cd69da9d0bcda4bfe1400fd19": "dc1f1332c3bbb0688ce5cc07bf78b719f5f9f549de5f0725493b705c41748dec",  # experiments/study/pair_mu.toml (declares reproduces)
    "9eb3e480c894b5bc34df43b5b9a8de0d7f73faa83a3f65cbeb7e49152b4225f2": "82e15f9008cd583a3af79c9689770e8de7646b09322d1ecfd1d153b940b451e2",  # experiments/study/pair_records.toml (declares reproduces)
    # experiments/study/single_isolated.toml (declares reproduces)
    "9a9e8639340c6742f144c3a5eee10f4e5d01d648a5ae3fe097441832f7061a34": "740a608956d013e4f9f9a57339b973a7409ce0f1f55a9322ee58b8ba12740eec",
    "a7884a051c76c657764f6b0fdadf29aeabb15cf2d539a42ad52e0341048c5d61": "19af4ddbe7eff219f664da68827d55ff6741dd8ac0e43e23f98deb0c4a9303a5",  # experiments/risk/fixed_pair.toml (session 21)
    "a96b3a7a523ad673a30620482f99af6dbe405d5e25d8dd6eb1448c9b1b8e00e5": "f3a55921fe5950299f3d307d982b7299e8774974b41e24b05d5b62dd6ec1d324",  # experiments/risk/isolated.toml (session 21)
    "26d2a268b3f4a622628565cd51e3367cf1c79becaa7c01aec4e1f43cf88b8054": "f9c42487b3ad4b044644d20558a72579ee254c36dab4f07defbe929c5049175c",  # experiments/risk/seed2/fixed_pair.toml
    "169bb8d74abd642f9a11b0ed00ae026bdc51595cdabc07f759e2d75a4ec4ac63": "792ca848b7699a1606f1904541f65233e4b1d967c180bd85f4128a4528dbafbf",  # experiments/risk/seed2/isolated.toml
}

#: The identity of the files with a [hazard], which no run depends on: since the hazard left the identity, their
#: sha256 of the canonical definition without its ``hazard`` entry (the pin above is still their canonical JSON's).
HAZARD_IDENTITIES = {
    "30f757d6a000b675d5a77664f7ebaac77f5f8fe2bdaaa81c5a883ef996a93fda": "3d9262abc04f842b1b695462aae97e3c7c5c028882c6fb38d85a52f450f1b5df",  # experiments/risk/fixed_pair.toml
    "7ee6d0bbad225fc7ce1b98b350144c895ed0d284696c10d4e0c60c6e1901feaf": "64fc42a22367fe253b24e30fc3e9836a2621b367c692dc9f7be87634a2cdbdfc",  # experiments/risk/fixed_pair.toml (yielding)
    "2ac35eca7fc1effebf5cc3dea300b01aadfa0cc86abb47b348e411247cb9c803": "e36e9c2fdea0577b1f73173500db4effca2a2727e81f6407fcdfa13484bfca68",  # experiments/risk/isolated.toml
    "8e4b705fc73ef76afaf17a43eb886385aa0233150b9d597de3b98ff0fa68b8cf": "87172a0dd106c497e3d120dd551dfa9f9882ac768b6799754a4df431a76f6d84",  # experiments/risk/isolated.toml (yielding)
    "d492a28de53b98b32b9f97c777010c9eb02c02dfe0a60221d79efa61f2ba4297": "18ff032947db1618ce6c8bd58a682e57cc433745d20a74253a1c4e3235420566",  # experiments/risk/fixed_pair.toml (fitted scenario)
    "9b8923b0aa6b1e0b7753b436bf63cf492e61951d6e15670e6b7589efe5611375": "9364efe22b86c445b311bde449ccf19393a749628c5f0f6e9f4cff43e66a9a41",  # experiments/risk/isolated.toml (fitted scenario)
    # [design] is not part of the identity: the same as the fitted-scenario versions without it
    "55b8a109c6a7fe493d3cf046f0681351cd1070678c42155b611b7cb4991cc95c": "18ff032947db1618ce6c8bd58a682e57cc433745d20a74253a1c4e3235420566",  # experiments/risk/fixed_pair.toml ([design])
    "88dc01b72bd04d6cc226d840a04e24e42421faa9c2bb9dc91a42aab11c0fbfde": "9364efe22b86c445b311bde449ccf19393a749628c5f0f6e9f4cff43e66a9a41",  # experiments/risk/isolated.toml ([design])
    "76706a47b9ed8d9b9c00281719f78adbbf7cc7ecaa91ed77f8fc343f9cafa29d": "f30423076bf791f10e274b0f0743bda704505337bda66785bf6631aedaf67b47",  # experiments/risk/fixed_pair.toml (calibration 3)
    "a9c66c0e67c4e663ca9e1a34a5de92a19ee03c1d8baacb45bb4cf61b70167667": "1190d4e22c8eaa71ec0e300d71dc4c348397c36780196be326b7c93f305de0ae",  # experiments/risk/isolated.toml (calibration 3)
    "3fd94462383c2c24ee90e370f9f660432ad80b2a147abbcefbc4f63eac0b23b9": "4fe970ab06ea26a4a9f36d1b5471df56e80d0360ded99b62e91a6b450eac5e03",  # experiments/risk/fixed_pair.toml (calibration 4)
    "f92271bfab4de9cbe54273e9251be8f1481ef9bedc9860afe355b5bfabb6cfaf": "fa04f6d5fb7b0ea7dbfe90b50324099a7bc2542d288e341f259d7a2976910475",  # experiments/risk/isolated.toml (calibration 4)
    "7e603f72ad6dc2cc4b5c236cb38f39ae5a01f44568c2bf98c9066e3225e5bf54": "e8a52964ed05bb590075e96c91a507adfa7db174d9a1f1cf345a835553b0feb7",  # experiments/risk/fixed_pair.toml (calibration 5)
    "06dbe7e36e949190951cf046a9f82a161824739cfba7655e097b2799acfd9aac": "bb00a5032692533bf1de73116dde6e4b73e6ca5656a40f2eb4b315d16eda8a2b",  # experiments/risk/isolated.toml (calibration 5)
    "a7884a051c76c657764f6b0fdadf29aeabb15cf2d539a42ad52e0341048c5d61": "e8a52964ed05bb590075e96c91a507adfa7db174d9a1f1cf345a835553b0feb7",  # experiments/risk/fixed_pair.toml (session 21)
    "a96b3a7a523ad673a30620482f99af6dbe405d5e25d8dd6eb1448c9b1b8e00e5": "bb00a5032692533bf1de73116dde6e4b73e6ca5656a40f2eb4b315d16eda8a2b",  # experiments/risk/isolated.toml (session 21)
    "26d2a268b3f4a622628565cd51e3367cf1c79becaa7c01aec4e1f43cf88b8054": "768a20c21d19f144dd0ddcc36a279b7c66038e0399b9ad5e0e12b4d13143632d",  # experiments/risk/seed2/fixed_pair.toml
    "169bb8d74abd642f9a11b0ed00ae026bdc51595cdabc07f759e2d75a4ec4ac63": "4c9942a1608fa2898b61a701a0267b8ef007bb560e3f4671f7160b3727d7ca03",  # experiments/risk/seed2/isolated.toml
}


#: The rare-event experiment files (a ``[rare_event]`` table): sha256 of the file's bytes -> their definition's sha256
#: (:class:`~stochpound.experiment.RareEventDefinition`, the identity their stores record).
RARE_EVENT_IDENTITIES = {
    "334009d34229ca1b82aaa3f0a305732695a9825a3ab9c83693f8fc146bd94a0f": "7f099bad648c8be51dff8c93cd91511952c3b70fab51908379d1e6bdda6087d1",  # experiments/stochastic/rare/firm_flexible_fixed.toml
    "a86a694832d378aa619dca8fca259c28e8bf762e4b6d3c7d017da55ac3279763": "4f0d02cf7b53c7bc373823d949c0e94866a0b2f09b887f6c4324caca42af8388",  # experiments/stochastic/rare/firm_flexible_mu005.toml
    "ec378e3a494c6e31fcb09f65d669d44b4487eb3d382c7d0aeb16942d0ca2e349": "64cc94e1c5753de5845e965f83b0510842d334ca54f07eae1f1c5125491b2328",  # experiments/stochastic/rare/firm_flexible_mu008.toml
    "efc4757c4e09f0f4a9ed01b284724b523407af788d905a0a33cdd22cbad0cdd0": "65aafdd9f39b7c25fdc848ee568cdf50ca2c09c74103ba9d24387e23c2c0d222",  # experiments/stochastic/rare/firm_flexible_mu012.toml
    "f827f75d6f9c342da053eb337ec10ef53797b000eaf498c2c9a26df8cea61cd1": "8a29ea79ec11695a16cbd9e7f524753993dd051e151074247099baf7dde8d137",  # experiments/stochastic/rare/firm_stiff_fixed.toml
    "7984e14ce289a3a3847d1dbdbb67952f6e3f467439cec6e12464d4ff30db1193": "fcbaf4d859ec89740f7539a9c875a54cbd52945098b7a02a6eb98f7c36178017",  # experiments/stochastic/rare/firm_stiff_mu005.toml
    "557bf1e1a19f811a5ee9c0f743ad498ec0de4793adb35be96d97cf8e39a4b890": "31c4b1d966ccb5ae126993b23f86a87874f0a5bf20cd60ed7de0b4e083bdb8c9",  # experiments/stochastic/rare/firm_stiff_mu008.toml
    "2b836ff1eb087e3d41b69383eb09fbc379a6379f11bb965681357e9c468900b5": "57bddcfdffe879ac7eaf64759169075be2339bd7ab1239d9e4bb2df4f07da718",  # experiments/stochastic/rare/firm_stiff_mu012.toml
    "0ded8ea9da1b4128460d61a7bc178e567073b5a30c4b81416e12a4d82ed3721c": "64dbaa227e73326e05a829c6fd9e1d343b1b25e235acb18f8e7b0648a2679df7",  # experiments/stochastic/rare/soft_flexible_fixed.toml
    "7586570de6e7230ccd8dfb0e344e1edc3c26a01b3f3bbbcd2bf75b77185750ec": "9aadc08581fbb338a364210f31d43368c6d27c2aaec4780f8763004dee2c71ba",  # experiments/stochastic/rare/soft_flexible_mu005.toml
    "04ea4103b1e039ddef7c7b19044c576fe00331629b737b27a1430aba78196264": "988400fa200a1b15a1f4d2c85f1b6532a5060080b6e603da850ca6590d5771fb",  # experiments/stochastic/rare/soft_flexible_mu008.toml
    "d9467476630486f3c8ec21df6bd33fdfb6398ec762120e1d55d3e5ca9528d423": "85fa29fa45fdd70284e2634f66793170a7bc4f5530a978806dc0cccbbf4e9d53",  # experiments/stochastic/rare/soft_flexible_mu012.toml
    "d924d0961906bca7993f58cdbc7a633d6146da86d71ffb941fb9fb58a238c673": "e279406d023ede9fddbbe3cd204c135e983b49af70802fe370fde01fcd784019",  # experiments/stochastic/rare/soft_stiff_fixed.toml
    "22743ad50abaf01736c04c9d31dfd4abe6d5f51018357eb6d072c03c1325b3ed": "f8a71ad9c2ca0a02732fdcce1cfe51cda8696d905771bc2fddbf66ad5e33986b",  # experiments/stochastic/rare/soft_stiff_mu005.toml
    "eed017de96ea0db6bf3000985a3a025807d94a17ad7718c25e920e11785557e0": "29f41853be0ba7e1c39d1dc1734f01cf353e0163e089a0ef907a0b84f396855b",  # experiments/stochastic/rare/soft_stiff_mu008.toml
    "423bf5b07ae21aa45fd555446d4f1e17d2f6be3512d71c37cb19191a86031742": "97a3398103e84619d2a851e1e2e4675b98b3db67e3b12a919148fc9f5ce903f2",  # experiments/stochastic/rare/soft_stiff_mu012.toml
}
RARE_EVENT_FILES = sorted(p for p in (ROOT / "experiments").glob("**/*.toml") if "scenes" not in p.parts and is_rare_event_file(p))


def test_rare_event_files_keep_their_identity() -> None:
    """Every rare-event experiment file is pinned, and gives the definition (sha256) of its pin."""
    assert RARE_EVENT_FILES, "the rare-event files of experiments/stochastic/rare/"
    for path in RARE_EVENT_FILES:
        file_sha256 = hashlib.sha256(path.read_bytes()).hexdigest()
        assert file_sha256 in RARE_EVENT_IDENTITIES, f"{path}: pin its version in RARE_EVENT_IDENTITIES ({file_sha256})"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # proposal = "acs" warns that it is not certified on peaks over time
            assert load_rare_event(path).sha256 == RARE_EVENT_IDENTITIES[file_sha256], path


def test_experiment_files_keep_their_identity() -> None:
    """Every experiment file whose version is pinned gives the same canonical definition (sha256 of its JSON) as before,
    and the same identity unless it has a hazard (whose identity leaves the hazard out, pinned apart)."""
    checked = 0
    for path in EXPERIMENTS:
        file_sha256 = hashlib.sha256(path.read_bytes()).hexdigest()
        pinned = IDENTITIES.get(file_sha256)
        if pinned is None:
            continue
        definition, _ = load_definition(path)
        source = definition.pop("scene_source", None)  # new since the pins, outside the identity: the scene file's name and sha256
        scene_path = tomllib.loads(path.read_text()).get("experiment", {}).get("scene")
        assert source == (None if scene_path is None else {"file": scene_path, "sha256": hashlib.sha256((path.parent / scene_path).read_bytes()).hexdigest()}), path
        site = definition.pop("site", None)  # new since the pins, outside the identity: how the [site] scenario was obtained
        table = tomllib.loads(path.read_text()).get("site")
        assert site == (None if table is None else {"scenario": "fitted", "curves": table["curves"]} if table.get("scenario") == "fitted"
                        else {"scenario": "given"}), path
        assert hashlib.sha256(canonical_json(definition).encode()).hexdigest() == pinned, path
        for key, value in (("scene_source", source), ("site", site)):
            if value is not None:
                assert definition_sha256({**definition, key: value}) == definition_sha256(definition), path
        assert ("hazard" in definition) == (file_sha256 in HAZARD_IDENTITIES), path
        assert definition_sha256(definition) == HAZARD_IDENTITIES.get(file_sha256, pinned), path
        checked += 1
    assert checked >= len(EXPERIMENTS) - 2, "most experiment files are pinned: pin the new versions"


@pytest.mark.parametrize("path", EXPERIMENTS, ids=lambda p: str(p.relative_to(ROOT)))
def test_read_definition_keeps_the_canonical_definition(path: Path) -> None:
    """From the parsed dict, from a store's JSON attribute, and from its text: the same dict and sha256; axes are floats."""
    definition, _ = load_definition(path)
    store = xr.Dataset(attrs={"definition": canonical_json(definition)})
    for source in (definition, store, canonical_json(definition)):
        typed = read_definition(source)
        assert typed.sha256 == definition_sha256(definition)
        assert canonical_json(typed.to_dict()) == canonical_json(definition)
        for axis in [*typed.gaps, *([typed.mu] if typed.mu else [])]:
            assert all(isinstance(v, float) for v in axis.values)
    typed = read_definition(store)
    assert [m.label for m in typed.motions] == [m["label"] for m in definition["motions"]]
    assert typed.output.buildings == tuple(definition["output"]["buildings"])
    assert typed.solver.rtol == definition["solver"]["rtol"]
    assert Experiment(typed).sha256 == Experiment(definition).sha256


def test_read_definition_types_and_errors() -> None:
    """Gap and μ axes, motions and the errors of a store without a definition."""
    definition, _ = load_definition(ROOT / "experiments" / "study" / "pair_mu.toml")
    typed = read_definition(definition)
    assert isinstance(typed, Definition) and read_definition(typed) is typed
    assert typed.mu is not None and typed.mu.has_fixed_base and FIXED_BASE in typed.mu.values
    assert not any(is_fixed_base(m) for m in typed.mu.finite_values)
    with pytest.raises(ExperimentError, match="no definition attribute"):
        read_definition(xr.Dataset())
    broken = copy.deepcopy(definition)
    del broken["solver"]
    with pytest.raises(ExperimentError, match="solver"):
        read_definition(broken)


def test_reproduces_declares_a_study_part() -> None:
    """The study's files declare the part they reproduce; a definition without the field (a store written before it) reads None;
    a value that is not a registered study's part is refused, naming the field and the allowed values."""
    definition, _ = load_definition(ROOT / "experiments" / "study" / "pair_mu.toml")
    assert read_definition(definition).reproduces == "agarwal2004:pair_mu"
    older = {key: value for key, value in definition.items() if key != "reproduces"}
    assert read_definition(xr.Dataset(attrs={"definition": canonical_json(older)})).reproduces is None
    assert read_definition(load_definition(ROOT / "experiments" / "quickstart.toml")[0]).reproduces is None
    data = tomllib.loads((ROOT / "experiments" / "study" / "harmonic.toml").read_text())
    for wrong in ("agarwal2004", "agarwal2004:pair", "thesis:gap", 3):
        data["experiment"]["reproduces"] = wrong
        with pytest.raises(ExperimentError, match=r"experiment\.reproduces: must be one of agarwal2004:harmonic, .*agarwal2004:pair_records, got"):
            parse_experiment(data, base_dir=ROOT / "experiments" / "study")


def test_fixed_base_rule() -> None:
    """μ = ∞ (a float or JSON's "inf") is a fixed base, and only that."""
    assert is_fixed_base(math.inf) and is_fixed_base("inf") and is_fixed_base(np.float64(np.inf))
    assert not is_fixed_base(0.0) and not is_fixed_base(0.1) and not is_fixed_base(1e300)
    assert value_text("mu", math.inf) == "fixed" and value_text("mu", 0.1) == "0.1"


@pytest.mark.parametrize(("name", "gap"), [("gap", True), ("gap_top", True), ("gap_wall_1", True), ("gap_", False), ("gaps", False), ("mu", False), ("gap-x", False)])
def test_gap_axis_rule(name: str, gap: bool) -> None:
    """One rule names gap axes for the parser and the report (cm labels)."""
    assert is_gap_axis(name) is gap
    assert (value_text(name, 0.02) == "2 cm") is gap


MOAT = ROOT / "experiments" / "laws" / "moat_wall.toml"


def _moat(grid: dict, walls: list[dict] | None = None) -> dict:
    """The moat-wall experiment with ``grid`` and, if given, ``walls`` instead of its base scene's walls."""
    data = tomllib.loads(MOAT.read_text())
    if walls is not None:
        data["scene"]["wall"] = walls
    data["grid"] = grid
    return data


def test_gap_axis_sets_walls() -> None:
    """The file's ``gap_wall`` axis gives each grid point the scene that a variant repeating its wall tables at that gap gives
    (and, at inf, walls that are never reached)."""
    compact = Experiment(load_definition(MOAT)[0])
    gap_axis = compact.contract.gaps[0]
    assert gap_axis.name == "gap_wall" and gap_axis.walls == (0, 1) and gap_axis.contacts == ()
    data = tomllib.loads(MOAT.read_text())
    walls = data["scene"].pop("wall")
    assert [w["side"] for w in walls] == ["left", "right"]
    variants: dict[str, dict] = {"none": {}}
    for gap in (g for g in gap_axis.values if math.isfinite(g)):
        variants[f"w{round(gap * 100)}"] = {"scene": {"wall": [{**wall, "gap": gap} for wall in walls]}}
    data["variants"] = {"moat": variants}
    data["grid"] = {"mu": data["grid"]["mu"]}
    variant_form = Experiment(parse_experiment(data))
    assert len(list(variant_form.points("case"))) == len(list(compact.points("case")))
    compared = 0
    for point in compact.points("case"):
        labels = dict(point.labels)
        scene = compact.structure(point)
        if math.isinf(labels["gap_wall"]):
            assert [w["gap"] for w in scene["wall"]] == [math.inf, math.inf]  # walls never reached: the variant without walls
            twin = next(p for p in variant_form.points("case") if dict(p.labels) == {"moat": "none", "mu": labels["mu"]})
            assert "wall" not in variant_form.structure(twin) or not variant_form.structure(twin)["wall"]
            continue
        twin = next(p for p in variant_form.points("case") if dict(p.labels) == {"moat": f"w{round(labels['gap_wall'] * 100)}", "mu": labels["mu"]})
        assert scene == variant_form.structure(twin)
        compared += 1
    assert compared == 8
    compact.validate()


def test_gap_axis_wall_errors() -> None:
    """Walls out of range, a scene without walls, and a wall-only axis leave the contacts alone."""
    with pytest.raises(ExperimentError, match=r"grid.gap_wall.walls: must be a non-empty list of wall indices in 0..1, got \[2\]"):
        parse_experiment(_moat({"gap_wall": {"values": [0.1], "walls": [2]}}))
    with pytest.raises(ExperimentError, match="grid.gap_wall.walls: the base scene has no wall"):
        parse_experiment(_moat({"gap_wall": {"values": [0.1], "walls": [0]}}, walls=[]))
    with pytest.raises(ExperimentError, match="give walls"):
        parse_experiment(_moat({"gap": [0.1]}))
    pair = tomllib.loads((ROOT / "experiments" / "quickstart.toml").read_text())
    n_contacts = len(parse_experiment(pair, base_dir=ROOT / "experiments")["scene"]["contact"])
    assert n_contacts > 0
    with pytest.raises(ExperimentError, match="grid.gap_w.walls: the base scene has no wall"):
        parse_experiment({**pair, "grid": {"gap_w": {"values": [0.1], "walls": [0]}}}, base_dir=ROOT / "experiments")


def test_report_names_the_gap_axis_of_walls() -> None:
    """The report's table of contacts gives a wall's gap as the axis that sets it, read from the store's definition alone."""
    from stochpound.report.sections._description import StoreDefinition, contacts_table

    definition = parse_experiment(_moat({"mu": {"values": [0.05, 0.1], "buildings": ["B1"]}, "gap_wall": {"values": [0.05, 0.1, "inf"], "walls": [0, 1]}}))
    store = xr.Dataset(attrs={"definition": canonical_json(definition)})
    table = contacts_table([StoreDefinition("moat", store)])
    assert table is not None
    cells = set(table.frame.astype(str).values.ravel())
    assert "{0.05, 0.1, ∞} (axis gap_wall)" in cells
